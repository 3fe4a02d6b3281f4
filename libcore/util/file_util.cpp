#include "libcore/util/file_util.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <mutex>
#include <system_error>
#include <vector>

#include "libcore/util/error.h"
#include "libcore/util/resources.h"

namespace hairgen {
namespace fs = std::filesystem;
namespace {

// ---------------------------------------------------------------------------------------------- inputs

template <typename Container>
Container readWhole(const fs::path& path) {
  InputFile file(path);
  Container data(static_cast<size_t>(file.size()), 0);
  file.read(data.data(), data.size());
  return data;
}

// ------------------------------------------------------------------------- the interrupt cleanup table

// Temporaries of writes in flight, readable from a signal handler: a fixed table of paths, each slot
// free (0), being filled (1) or live (2). A handler unlinks only live slots.
struct TemporarySlot {
  std::atomic<int> state{0};
  char path[4096];
};
std::array<TemporarySlot, 256> gTemporaries;

int registerTemporary(const fs::path& path) {
  const std::string text = path.string();
  if (text.size() >= sizeof gTemporaries[0].path) return -1;
  for (size_t i = 0; i < gTemporaries.size(); ++i) {
    int expected = 0;
    if (!gTemporaries[i].state.compare_exchange_strong(expected, 1)) continue;
    std::memcpy(gTemporaries[i].path, text.c_str(), text.size() + 1);
    gTemporaries[i].state.store(2);
    return int(i);
  }
  return -1;  // more writes in flight than slots: still written, only not cleaned on a signal
}

void releaseTemporary(int slot) {
  if (slot >= 0) gTemporaries[size_t(slot)].state.store(0);
}

extern "C" void removeTemporariesAndExit(int signal) {
  for (TemporarySlot& slot : gTemporaries)
    if (slot.state.load() == 2) ::unlink(slot.path);
  ::_exit(128 + signal);
}

// Files committed by this command, removed if it fails.
std::mutex gCommittedMutex;
std::vector<fs::path> gCommitted;

void recordCommitted(const fs::path& path) {
  std::lock_guard<std::mutex> lock(gCommittedMutex);
  gCommitted.push_back(path);
}

// ---------------------------------------------------------------------------------------------- outputs

std::string hostName() {
  char name[256] = {};
  if (::gethostname(name, sizeof name - 1) != 0 || !name[0]) return "host";
  std::string host(name);
  for (char& c : host)
    if (c == '-' || c == '/') c = '_';  // the name's fields are split on '-'
  return host;
}

// Where a write to `requested` goes: a link's destination; what kind of file is there.
struct Destination {
  fs::path path;
  bool direct = false;  // a device, FIFO or socket: written in place
  int descriptor = -1;  // a descriptor this process has open (/dev/stdout, /dev/fd/N): written through it
};

// The number N when `text` names descriptor N of this process: /dev/stdout, /dev/stderr, /dev/fd/N,
// or N under /proc's fd folder of this process or of one of its threads (self, thread-self, PID,
// self/task/TID, PID/task/TID); −1 otherwise.
int descriptorNumberIn(const std::string& text) {
  if (text == "/dev/stdout") return 1;
  if (text == "/dev/stderr") return 2;
  const size_t slash = text.rfind('/');
  if (slash == std::string::npos || slash + 1 == text.size() || text.size() - slash - 1 > 9 ||
      text.find_first_not_of("0123456789", slash + 1) != std::string::npos)
    return -1;
  const std::string folder = text.substr(0, slash + 1), pid = std::to_string(::getpid());
  auto isNumber = [](const std::string& t) {
    return !t.empty() && t.find_first_not_of("0123456789") == std::string::npos;
  };
  bool ours = folder == "/dev/fd/";
  for (const std::string& process : {std::string("self"), std::string("thread-self"), pid}) {
    const std::string base = "/proc/" + process + "/";
    if (folder == base + "fd/") ours = true;
    // PROCESS/task/TID/fd/: a thread of this process.
    if (process != "thread-self" && folder.size() > base.size() + 9 &&
        folder.compare(0, base.size() + 5, base + "task/") == 0 &&
        folder.compare(folder.size() - 4, 4, "/fd/") == 0 &&
        isNumber(folder.substr(base.size() + 5, folder.size() - 4 - base.size() - 5)))
      ours = true;
  }
  return ours ? std::stoi(text.substr(slash + 1)) : -1;
}

// The descriptor of this process that `requested` names, or that a link on the way to it names (see
// descriptorNumberIn); −1 for a path that names none. A named descriptor that is not open, or is
// open only for reading, is an InputError: nothing could be written through it. Opening such a path
// again would open the file behind it anew (truncating a log that stdout is appended to); writing
// through the descriptor writes where the shell's redirection points, at its offset, appending where
// it appends.
int descriptorNamed(const fs::path& requested) {
  std::error_code ec;
  fs::path path = requested.lexically_normal();
  for (int depth = 0; depth < 40; ++depth) {
    if (const int fd = descriptorNumberIn(path.string()); fd >= 0) {
      const int flags = ::fcntl(fd, F_GETFL);
      if (flags == -1)
        throw InputError({requested.string(), 0}, "names descriptor " + std::to_string(fd) +
                                                      ", which this command does not have open");
      if ((flags & O_ACCMODE) == O_RDONLY)
        throw InputError({requested.string(), 0},
                         "names descriptor " + std::to_string(fd) + ", which is open for reading only");
      return fd;
    }
    if (!fs::is_symlink(fs::symlink_status(path, ec))) return -1;
    const fs::path to = fs::read_symlink(path, ec);
    if (ec) return -1;
    path = (to.is_absolute() ? to : path.parent_path() / to).lexically_normal();
  }
  return -1;
}

Destination destinationOf(const fs::path& requested) {
  std::error_code ec;
  if (const int fd = descriptorNamed(requested); fd >= 0) {
    struct stat st {};
    if (::fstat(fd, &st) == 0 && S_ISDIR(st.st_mode))
      throw InputError({requested.string(), 0}, "is a directory; name a file to write");
    return {requested, true, fd};
  }
  const fs::file_status status = fs::status(requested, ec);  // through any links
  if (fs::is_directory(status))
    throw InputError({requested.string(), 0}, "is a directory; name a file to write");
  // A device, FIFO or socket, however reached (/dev/stdout is a link to /proc/self/fd/1): written as is.
  if (fs::exists(status) && !fs::is_regular_file(status)) return {requested, true};
  // A link to a file, or a dangling one: the file it names is replaced, the link stays.
  fs::path path = requested;
  for (int depth = 0; fs::is_symlink(fs::symlink_status(path, ec)); ++depth) {
    if (depth == 40) throw InputError({requested.string(), 0}, "too many levels of symbolic links");
    const fs::path to = fs::read_symlink(path, ec);
    if (ec) throw IoError({requested.string(), 0}, "cannot follow the symbolic link: " + ec.message());
    path = to.is_absolute() ? to : path.parent_path() / to;
  }
  return {path, false};
}

// Removes temporaries beside `target` that a process of this host left when it died (a kill -9, a
// lost node): NAME.tmp-HOST-PID-N whose PID no longer runs.
void sweepStaleTemporaries(const fs::path& target, const std::string& prefix) {
  std::error_code ec;
  const fs::path dir = target.parent_path().empty() ? fs::path(".") : target.parent_path();
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.compare(0, prefix.size(), prefix) != 0) continue;
    const std::string rest = name.substr(prefix.size());  // PID-N
    const size_t dash = rest.find('-');
    if (dash == std::string::npos) continue;
    char* parsed = nullptr;
    const long pid = std::strtol(rest.c_str(), &parsed, 10);
    if (parsed != rest.c_str() + dash || pid <= 0) continue;
    if (::kill(pid_t(pid), 0) == 0 || errno != ESRCH) continue;  // alive, or not ours to judge
    std::error_code ignored;
    fs::remove(it->path(), ignored);
  }
}

// A fresh name beside `target` (its folder created), registered for cleanup.
fs::path temporaryBeside(const fs::path& target, int& slot) {
  static std::atomic<unsigned> counter{0};
  static const std::string host = hostName();
  const fs::path dir = target.parent_path();
  if (!dir.empty()) {
    std::error_code ec;
    fs::create_directories(dir, ec);
    if (ec) throw IoError({dir.string(), 0}, "cannot create directory: " + ec.message());
  }
  const std::string prefix = target.filename().string() + ".tmp-" + host + "-";
  sweepStaleTemporaries(target, prefix);
  fs::path temporary = target;
  temporary.replace_filename(prefix + std::to_string(::getpid()) + "-" + std::to_string(counter++));
  slot = registerTemporary(temporary);
  return temporary;
}

void renameInto(const fs::path& temporary, const fs::path& target) {
  std::error_code ec;
  fs::rename(temporary, target, ec);
  if (ec) throw IoError({target.string(), 0}, "cannot rename into place: " + ec.message());
}

// Copies a finished file to an open descriptor, at its offset, after whatever the command had already
// printed to its own streams (still in their buffers, it would otherwise come after).
void copyToDescriptor(const fs::path& from, int fd, const fs::path& name) {
  std::cout.flush();
  std::cerr.flush();
  std::fflush(nullptr);
  std::ifstream in(from, std::ios::binary);
  std::vector<char> buffer(1 << 16);
  while (in) {
    in.read(buffer.data(), std::streamsize(buffer.size()));
    for (size_t done = 0, n = size_t(in.gcount()); done < n;) {
      const ssize_t wrote = ::write(fd, buffer.data() + done, n - done);
      if (wrote < 0 && errno == EINTR) continue;
      if (wrote <= 0) throw IoError({name.string(), 0}, std::string("write failed: ") + std::strerror(errno));
      done += size_t(wrote);
    }
  }
  if (in.bad()) throw IoError({name.string(), 0}, "write failed: cannot read back what was written");
}

// Copies a finished file into a device or FIFO.
void copyInto(const fs::path& from, const fs::path& device) {
  const int fd = ::open(device.c_str(), O_WRONLY | O_CLOEXEC);
  if (fd < 0) throw IoError({device.string(), 0}, std::string("cannot write: ") + std::strerror(errno));
  try {
    copyToDescriptor(from, fd, device);
  } catch (...) {
    ::close(fd);
    throw;
  }
  ::close(fd);
}

}  // namespace

void requireRegularFile(const fs::path& path) {
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  const FileLoc where{path.string(), 0};
  if (!fs::exists(status)) throw InputError(where, "cannot open: no such file");
  if (fs::is_directory(status)) throw InputError(where, "is a directory, expected a file");
  if (!fs::is_regular_file(status))
    throw InputError(where, "is not a regular file (a FIFO, device or socket); name a file, not a stream");
}

InputFile::InputFile(const fs::path& path) : name_(path.string()) {
  const FileLoc where{name_, 0};
  // O_NONBLOCK: opening a FIFO must not wait for a writer; fstat then refuses it.
  fd_ = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd_ < 0) throw InputError(where, std::string("cannot open: ") + std::strerror(errno));
  struct stat st {};
  std::string refusal;
  if (::fstat(fd_, &st) != 0)
    refusal = std::string("cannot read: ") + std::strerror(errno);
  else if (S_ISDIR(st.st_mode))
    refusal = "is a directory, expected a file";
  else if (!S_ISREG(st.st_mode))
    refusal = "is not a regular file (a FIFO, device or socket); name a file, not a stream";
  else if (uint64_t(st.st_size) > memoryBudget())
    refusal = "is " + formatBytes(uint64_t(st.st_size)) + ", more than the " + formatBytes(memoryBudget()) +
              " of memory this machine has free for it";
  if (!refusal.empty()) {
    ::close(fd_);
    throw InputError(where, refusal);
  }
  size_ = uint64_t(st.st_size);
}

InputFile::~InputFile() {
  ::close(fd_);
}

void InputFile::read(void* out, size_t bytes) {
  if (bytes > size_ - position_) throw InputError({name_, 0}, "the file shrank while it was read");
  size_t done = 0;
  while (done < bytes) {
    const ssize_t n = ::read(fd_, static_cast<char*>(out) + done, bytes - done);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) throw IoError({name_, 0}, std::string("read failed: ") + std::strerror(errno));
    if (n == 0) throw InputError({name_, 0}, "the file shrank while it was read");
    done += size_t(n);
  }
  position_ += bytes;
}

void requireWritableOutput(const fs::path& target) {
  const Destination destination = destinationOf(target);  // a directory, a closed descriptor: refused
  if (destination.direct) return;
  // The nearest folder that exists on the way to the file's: the one a write creates folders in.
  std::error_code ec;
  fs::path folder = fs::absolute(destination.path, ec).parent_path();
  if (ec) folder = destination.path.parent_path();
  if (folder.empty()) folder = ".";
  while (!fs::exists(folder, ec) && folder.has_parent_path() && folder.parent_path() != folder)
    folder = folder.parent_path();
  if (fs::exists(folder, ec) && !fs::is_directory(folder, ec))
    throw InputError({folder.string(), 0}, "is not a folder, so " + target.string() + " cannot be written");
  if (::access(folder.c_str(), W_OK | X_OK) != 0)
    throw IoError({target.string(), 0},
                  std::string("cannot write in ") + folder.string() + ": " + std::strerror(errno));
}

std::string contentDigest(const fs::path& path) {
  // XXH64's round on each of four lanes (a rotate between multiplies carries every bit of a word into
  // every bit of its lane) and MurmurHash3's finaliser on the result; words read little-endian.
  constexpr uint64_t kP1 = 0x9e3779b185ebca87ull, kP2 = 0xc2b2ae3d27d4eb4full, kP3 = 0x165667b19e3779f9ull;
  auto round = [](uint64_t lane, uint64_t word) { return std::rotl(lane + word * kP2, 31) * kP1; };
  auto mix = [](uint64_t h) {
    h ^= h >> 33;
    h *= 0xff51afd7ed558ccdull;
    h ^= h >> 33;
    h *= 0xc4ceb9fe1a85ec53ull;
    return h ^ (h >> 33);
  };
  uint64_t lanes[4] = {kP1 + kP2, kP2, 0, 0 - kP1};
  // Not InputFile: its refusal of a file larger than the free memory would make the digest depend on
  // the machine, and the file is read in pieces here.
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) return "";
  struct stat st {};
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
    ::close(fd);
    return "";
  }
  std::vector<unsigned char> buffer(1 << 20);  // 1 MiB a read, a multiple of the 32 bytes a step takes
  uint64_t size = 0;
  bool ok = true;
  for (;;) {
    size_t filled = 0;
    while (filled < buffer.size()) {
      const ssize_t n = ::read(fd, buffer.data() + filled, buffer.size() - filled);
      if (n < 0 && errno == EINTR) continue;
      if (n < 0) ok = false;
      if (n <= 0) break;
      filled += size_t(n);
    }
    size += filled;
    std::fill(buffer.begin() + std::ptrdiff_t(filled),
              buffer.begin() + std::ptrdiff_t((filled + 31) / 32 * 32),
              0);  // the last step's missing bytes are zeros (the size is mixed in after)
    for (size_t at = 0; at < filled; at += 8) {
      uint64_t word = 0;
      for (int b = 7; b >= 0; --b) word = word << 8 | buffer[at + size_t(b)];
      lanes[(at / 8) & 3] = round(lanes[(at / 8) & 3], word);
    }
    if (!ok || filled < buffer.size()) break;
  }
  ::close(fd);
  if (!ok) return "";
  uint64_t hash = size * kP3;
  for (uint64_t lane : lanes) hash = mix(hash ^ round(0, lane)) * kP1;
  hash = mix(hash);
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(hash));
  return hex;
}

std::string readFileText(const fs::path& path) {
  return readWhole<std::string>(path);
}

std::vector<uint8_t> readFileBytes(const fs::path& path) {
  return readWhole<std::vector<uint8_t>>(path);
}

AtomicFile::AtomicFile(fs::path target) {
  const Destination destination = destinationOf(target);
  target_ = destination.path;
  descriptor_ = destination.descriptor;
  // A descriptor's file is written whole at the end, from a temporary in the system's folder.
  if (descriptor_ >= 0)
    temporary_ = temporaryBeside(fs::temp_directory_path() / target_.filename(), slot_);
  else if (!destination.direct)
    temporary_ = temporaryBeside(target_, slot_);
  const fs::path& path = destination.direct && descriptor_ < 0 ? target_ : temporary_;
  stream_.open(path, std::ios::binary | std::ios::trunc);
  if (!stream_) {
    const std::string reason = std::strerror(errno);
    releaseTemporary(slot_);
    throw IoError({target.string(), 0}, "cannot write: " + reason);
  }
}

AtomicFile::~AtomicFile() {
  if (committed_) return;
  stream_.close();
  if (!temporary_.empty()) {
    std::error_code ec;
    fs::remove(temporary_, ec);
  }
  releaseTemporary(slot_);
}

void AtomicFile::commit() {
  stream_.flush();
  const bool ok = static_cast<bool>(stream_);
  stream_.close();
  if (!ok || stream_.fail())
    throw IoError({target_.string(), 0}, "write failed (no space left on the device?)");
  if (descriptor_ >= 0) {
    copyToDescriptor(temporary_, descriptor_, target_);
    std::error_code ec;
    fs::remove(temporary_, ec);
  } else if (!temporary_.empty()) {
    renameInto(temporary_, target_);
    recordCommitted(target_);
  }
  releaseTemporary(slot_);
  committed_ = true;
}

void writeThroughTemporary(const fs::path& target, const std::function<void(const fs::path&)>& write) {
  const Destination destination = destinationOf(target);
  int slot = -1;
  // A device's folder (/dev) is no place for a temporary: the system's temporary folder is.
  const fs::path temporary = destination.direct
                                 ? temporaryBeside(fs::temp_directory_path() / target.filename(), slot)
                                 : temporaryBeside(destination.path, slot);
  try {
    write(temporary);
    if (destination.descriptor >= 0) {
      copyToDescriptor(temporary, destination.descriptor, destination.path);
      fs::remove(temporary);
    } else if (destination.direct) {
      copyInto(temporary, destination.path);
      fs::remove(temporary);
    } else {
      renameInto(temporary, destination.path);
      recordCommitted(destination.path);
    }
  } catch (...) {
    std::error_code ec;
    fs::remove(temporary, ec);
    releaseTemporary(slot);
    throw;
  }
  releaseTemporary(slot);
}

void writeFileAtomic(const fs::path& target, const void* data, size_t size) {
  AtomicFile file(target);
  file.stream().write(static_cast<const char*>(data), static_cast<std::streamsize>(size));
  file.commit();
}

void installInterruptCleanup() {
  static std::once_flag once;
  std::call_once(once, [] {
    for (int signal : {SIGINT, SIGTERM, SIGHUP}) {
      struct sigaction current {};
      if (::sigaction(signal, nullptr, &current) == 0 && current.sa_handler == SIG_IGN) continue;
      struct sigaction action {};
      action.sa_handler = removeTemporariesAndExit;
      sigemptyset(&action.sa_mask);
      ::sigaction(signal, &action, nullptr);
    }
  });
}

void discardCommittedOutputs() {
  std::lock_guard<std::mutex> lock(gCommittedMutex);
  for (const fs::path& path : gCommitted) {
    std::error_code ec;
    fs::remove(path, ec);
  }
  gCommitted.clear();
}

std::vector<fs::path> committedOutputs() {
  std::lock_guard<std::mutex> lock(gCommittedMutex);
  return std::vector<fs::path>(gCommitted.begin(), gCommitted.end());
}

void forgetCommittedOutputs() {
  std::lock_guard<std::mutex> lock(gCommittedMutex);
  gCommitted.clear();
}

}  // namespace hairgen
