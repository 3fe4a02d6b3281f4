#include "libcore/util/file_util.h"

#include <dirent.h>
#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <bit>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <mutex>
#include <system_error>
#include <thread>
#include <vector>

#include "libcore/util/error.h"
#include "libcore/util/mapped_file.h"
#include "libcore/util/resources.h"
#include "libcore/util/signal_slots.h"
#include "libcore/util/text.h"

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

// Temporaries of writes in flight, for the interrupt cleanup to remove: only live ones, whose file
// this process made (signal_slots.h).
struct TemporaryPath {
  char path[4096];
};
SignalSlots<TemporaryPath, 256> gTemporaries;

// Reserves a slot for `path` (being filled: the cleanup leaves it alone until markLive); −1 when every
// slot is taken (the write still happens, only a signal does not clean it).
int reserveTemporary(const fs::path& path) {
  const std::string text = path.string();
  if (text.size() >= sizeof(TemporaryPath::path)) return -1;
  const int slot = gTemporaries.claim();
  if (slot >= 0) std::memcpy(gTemporaries[slot].path, text.c_str(), text.size() + 1);
  return slot;
}

// The slot's file exists now, made by this process: a signal removes it.
void markLive(int slot) {
  gTemporaries.markLive(slot);
}

void releaseTemporary(int slot) {
  gTemporaries.release(slot);
}

extern "C" void removeTemporariesAndExit(int signal) {
  // A private temporary's path goes through its folder's descriptor (/proc/PID/fd/N/NAME): its empty
  // folder stays, for a later write beside it to sweep.
  gTemporaries.forEachLive([](const TemporaryPath& t) { ::unlink(t.path); });
  ::_exit(128 + signal);
}

// A file this process made and renamed into place: its name, and the device and inode of the file it
// created there, so that a cleanup removes that file and nothing that has taken its name since. What the
// name held before (a user's file, the command's own input) is kept under `backup`, a hard link beside
// it, until the command keeps its outputs or fails: then it is put back.
struct Committed {
  fs::path path;
  dev_t device = 0;
  ino_t inode = 0;
  fs::path backup;        // empty: the name held nothing, or no link could be made (`replaced`)
  int backupSlot = -1;    // the backup's entry in the interrupt cleanup table
  bool replaced = false;  // the name held a file that could not be kept: a failure leaves the new one
};

// Files committed by this command, in commit order; those from gKept on are removed if it fails.
std::mutex gCommittedMutex;
std::vector<Committed> gCommitted;
size_t gKept = 0;

void recordCommitted(const Committed& file) {
  std::lock_guard<std::mutex> lock(gCommittedMutex);
  gCommitted.push_back(file);
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
  // A regular file, a new name, or a symbolic link to a file or to nothing: the name itself is
  // replaced by the rename, as mv replaces it; nothing is written through a link.
  return {requested, false};
}

// The folders on the way to `file` (its name `target` for messages), root first: each that exists must
// be a folder (a link to one is followed); a missing one is made when `create`. A symbolic link that
// points nowhere is refused either way: no folder is made through a link. Returns the deepest folder
// that exists when done (the file's own after creating). Throws InputError for something on the way
// that is not a folder or is a dangling link, IoError for a folder that cannot be made or examined.
fs::path walkFolders(const fs::path& file, const std::string& target, bool create) {
  const fs::path folder = file.parent_path();
  fs::path walked, deepest = folder.is_absolute() ? folder.root_path() : fs::path(".");
  for (const fs::path& part : folder) {
    walked /= part;
    struct stat st {};
    if (::stat(walked.c_str(), &st) == 0) {
      if (!S_ISDIR(st.st_mode))
        throw InputError({walked.string(), 0}, "is not a folder, so " + target + " cannot be written");
      deepest = walked;
      continue;
    }
    if (errno != ENOENT)
      throw IoError({target, 0}, "cannot reach " + walked.string() + ": " + std::strerror(errno));
    if (::lstat(walked.c_str(), &st) == 0) {  // there, but stat found nothing behind it
      std::error_code ec;
      const fs::path to = fs::read_symlink(walked, ec);
      throw InputError({walked.string(), 0}, "is a symbolic link to " +
                                                 (ec ? std::string("nothing") : to.string()) +
                                                 ", which does not exist; hairgen makes no folder through a "
                                                 "link, so " +
                                                 target + " cannot be written");
    }
    if (!create) return deepest;
    if (::mkdir(walked.c_str(), 0777) != 0 && errno != EEXIST)
      throw IoError({walked.string(), 0}, std::string("cannot create directory: ") + std::strerror(errno));
    // Made, or made meanwhile by another process (a farm's tasks share folders): a folder either way?
    if (::stat(walked.c_str(), &st) != 0 || !S_ISDIR(st.st_mode))
      throw IoError({walked.string(), 0}, "cannot create directory: something else took its name");
    deepest = walked;
  }
  return deepest;
}

// A temporary's name beside `target` begins NAME.tmp-HOST- (PID-N follows): NAME cut so that the whole
// name fits a folder entry (255 bytes), so an output with a long name is written as any other.
std::string temporaryPrefix(const fs::path& target) {
  static const std::string host = hostName();
  const std::string name = target.filename().string();
  const std::string tail = ".tmp-" + host + "-";
  constexpr size_t kEntry = 255, kPidAndCounter = 2 * 20 + 2;  // "PID-N" and a spare byte
  const size_t room = kEntry > tail.size() + kPidAndCounter ? kEntry - tail.size() - kPidAndCounter : 0;
  return name.substr(0, std::min(name.size(), room)) + tail;
}

// The next name of the form temporaryPrefix() + PID-N beside `target`.
fs::path nextTemporaryName(const fs::path& target, const std::string& prefix) {
  static std::atomic<unsigned> counter{0};
  fs::path path = target;
  path.replace_filename(prefix + std::to_string(::getpid()) + "-" + std::to_string(counter++));
  return path;
}

// Removes what lies in a folder held open as `folderFd` (what a library left there too, through the
// descriptor: never a name, never a link followed; folders within are left), then closes it.
void emptyAndClose(int folderFd) {
  const int listing = ::dup(folderFd);
  if (DIR* d = listing >= 0 ? ::fdopendir(listing) : nullptr) {
    while (const dirent* e = ::readdir(d)) {
      const std::string name = e->d_name;
      if (name != "." && name != "..") ::unlinkat(folderFd, name.c_str(), 0);  // a folder: EISDIR, left
    }
    ::closedir(d);
  } else if (listing >= 0) {
    ::close(listing);
  }
  ::close(folderFd);
}

// Removes temporaries beside `target` that a process of this host left when it died (a kill -9, a
// lost node): regular files, and the private folders of writes by name (createPrivateTemporary), named
// NAME.tmp-HOST-PID-N whose PID no longer runs.
void sweepStaleTemporaries(const fs::path& target, const std::string& prefix) {
  std::error_code ec;
  const fs::path dir = target.parent_path().empty() ? fs::path(".") : target.parent_path();
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.compare(0, prefix.size(), prefix) != 0) continue;
    const std::string rest = name.substr(prefix.size());  // PID-N
    const size_t dash = rest.find('-');
    if (dash == std::string::npos || dash + 1 == rest.size() ||
        rest.find_first_not_of("0123456789", dash + 1) != std::string::npos)
      continue;  // not a name this code makes
    char* parsed = nullptr;
    const long pid = std::strtol(rest.c_str(), &parsed, 10);
    if (parsed != rest.c_str() + dash || pid <= 0) continue;
    if (::kill(pid_t(pid), 0) == 0 || errno != ESRCH) continue;  // alive, or not ours to judge
    std::error_code ignored;
    const fs::file_status status = it->symlink_status(ignored);
    if (fs::is_regular_file(status)) {
      fs::remove(it->path(), ignored);
    } else if (fs::is_directory(status)) {
      // A private folder: opened without following a link, and emptied through the descriptor, only
      // where it is this user's and private, as this code makes it.
      const int folderFd = ::open(it->path().c_str(), O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
      struct stat st {};
      if (folderFd < 0) continue;
      if (::fstat(folderFd, &st) != 0 || st.st_uid != ::geteuid() || (st.st_mode & 0077) != 0) {
        ::close(folderFd);
        continue;
      }
      // Only the one file this code makes there (named as the target): a folder of the user's that
      // someone renamed to this name keeps everything else, and stays.
      ::unlinkat(folderFd, target.filename().c_str(), 0);
      ::close(folderFd);
      ::rmdir(it->path().c_str());
    }
  }
}

// A temporary this process created, and the open descriptor it was created with.
struct Temporary {
  fs::path path;
  int fd = -1;
  int slot = -1;  // its entry in the interrupt cleanup table
  // A private temporary's (createPrivateTemporary): its folder, held open, its name, the file's name.
  int folderFd = -1;
  fs::path folder;
  std::string leaf;
};

// Creates a fresh temporary beside `target` (the folders on the way made, never through a dangling
// link): O_CREAT | O_EXCL | O_NOFOLLOW, so it is a new file of this process and never a name someone
// had put there (a link, a file); registered for cleanup on a signal.
// The folders on the way to `target` made for a write, and the stale temporaries beside it swept; the
// temporaries' prefix.
std::string prepareTemporaryBeside(const fs::path& target) {
  try {
    walkFolders(target, target.string(), true);
  } catch (const InputError& e) {
    // Found only while writing (the command did not check this output before its work): the write
    // failed, as a folder that cannot be made fails it.
    throw IoError(e.where(), e.message());
  }
  const std::string prefix = temporaryPrefix(target);
  sweepStaleTemporaries(target, prefix);
  return prefix;
}

Temporary createTemporaryBeside(const fs::path& target) {
  const std::string prefix = prepareTemporaryBeside(target);
  for (int attempt = 0;; ++attempt) {
    Temporary t;
    t.path = nextTemporaryName(target, prefix);
    t.slot = reserveTemporary(t.path);
    t.fd = ::open(t.path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0666);
    if (t.fd >= 0) {
      markLive(t.slot);
      return t;
    }
    const int error = errno;
    releaseTemporary(t.slot);
    if (error != EEXIST || attempt == 100)  // a name taken is someone else's: the next one is tried
      throw IoError({target.string(), 0}, std::string("cannot write: ") + std::strerror(error));
  }
}

// Removes a private temporary's file and its folder.
void removePrivateTemporary(const Temporary& t) {
  emptyAndClose(t.folderFd);
  ::rmdir(t.folder.c_str());  // only if empty, and never through a link: at worst one stays
}

// For a library that opens the file by name (writeThroughTemporary): a private folder beside `target`
// (mode 0700, a fresh name made by mkdir, which never follows or reuses a name someone put there) and a
// new file in it named as the target (the library may choose its format by the name's extension). No
// other user can swap the file for a link between its creation and the library's opening it by name, as
// they could beside the target in a folder they may write in (a farm's shared shot folder).
Temporary createPrivateTemporary(const fs::path& target) {
  const std::string prefix = prepareTemporaryBeside(target);
  for (int attempt = 0;; ++attempt) {
    const fs::path folder = nextTemporaryName(target, prefix);
    if (::mkdir(folder.c_str(), 0700) != 0) {
      const int error = errno;
      if (error != EEXIST || attempt == 100)
        throw IoError({target.string(), 0}, std::string("cannot write: ") + std::strerror(error));
      continue;
    }
    // Held open from now on and reached only through its descriptor: its name may be renamed away and
    // replaced by a link to someone's folder (a folder others may write in allows that), and nothing
    // here reads or writes through the name again but an rmdir, which removes only an empty folder and
    // never follows a link.
    Temporary t;
    t.folder = folder;
    t.folderFd = ::open(folder.c_str(), O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
    struct stat st {};
    if (t.folderFd < 0 || ::fstat(t.folderFd, &st) != 0 || st.st_uid != ::geteuid() ||
        (st.st_mode & 0077) != 0) {
      const int error = t.folderFd < 0 ? errno : EPERM;
      if (t.folderFd >= 0) ::close(t.folderFd);
      throw IoError({target.string(), 0}, "cannot write: the private folder " + folder.string() +
                                              " was replaced before it was opened (" + std::strerror(error) +
                                              ")");
    }
    t.leaf = target.filename().string();
    // The library opens the file by a name that goes through the descriptor (this process's, so a child
    // such as ffmpeg reaches it too).
    t.path = fs::path("/proc") / std::to_string(::getpid()) / "fd" / std::to_string(t.folderFd) / t.leaf;
    t.slot = reserveTemporary(t.path);
    t.fd = ::openat(t.folderFd, t.leaf.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0666);
    if (t.fd >= 0 && ::access(t.path.c_str(), W_OK) == 0) {
      markLive(t.slot);
      return t;
    }
    const int error = t.fd < 0 ? errno : ENOENT;  // no /proc: the descriptor's name cannot be given
    if (t.fd >= 0) ::close(t.fd);
    releaseTemporary(t.slot);
    removePrivateTemporary(t);
    throw IoError({target.string(), 0}, std::string("cannot write: ") + std::strerror(error));
  }
}

// A committed file named `target` that is the file `st` describes.
Committed committedAs(const fs::path& target, const struct stat& st) {
  Committed c;
  c.path = target;
  c.device = st.st_dev;
  c.inode = st.st_ino;
  return c;
}

// The device and inode of a file this process holds open; throws IoError when it cannot tell.
Committed identityOf(int fd, const fs::path& target) {
  struct stat st {};
  if (::fstat(fd, &st) != 0)
    throw IoError({target.string(), 0}, std::string("cannot write: ") + std::strerror(errno));
  return committedAs(target, st);
}

void renameInto(const fs::path& temporary, const fs::path& target) {
  std::error_code ec;
  fs::rename(temporary, target, ec);
  if (ec) throw IoError({target.string(), 0}, "cannot rename into place: " + ec.message());
}

// What `target` holds before a commit replaces it (a regular file, or a symbolic link itself, never
// followed), kept as a hard link beside it under a temporary's name, so a command that fails later puts
// it back: a failed command never costs a file that was there (its own input, written over in place).
// Sets `backup` and `backupSlot`, or `replaced` where the name holds a file no link could be made to (a
// file system without hard links).
void keepWhatIsThere(const fs::path& target, Committed& c) {
  struct stat st {};
  if (::lstat(target.c_str(), &st) != 0) return;  // a new name
  if (!S_ISREG(st.st_mode) && !S_ISLNK(st.st_mode)) return;
  const std::string prefix = temporaryPrefix(target);
  for (int attempt = 0; attempt <= 100; ++attempt) {
    const fs::path backup = nextTemporaryName(target, prefix);
    const int slot = reserveTemporary(backup);
    // linkat without AT_SYMLINK_FOLLOW: a link to the link itself, as rename replaces the link itself.
    if (::linkat(AT_FDCWD, target.c_str(), AT_FDCWD, backup.c_str(), 0) == 0) {
      markLive(slot);
      c.backup = backup;
      c.backupSlot = slot;
      return;
    }
    const int error = errno;
    releaseTemporary(slot);
    if (error != EEXIST) break;
  }
  c.replaced = true;
}

// Drops a committed file's backup: the new file stays.
void dropBackup(Committed& c) {
  if (!c.backup.empty()) ::unlink(c.backup.c_str());
  releaseTemporary(c.backupSlot);
  c.backup.clear();
  c.backupSlot = -1;
}

// Renames a finished temporary over `target` (a link there replaced, not followed), keeping what was
// there until the command keeps or discards its outputs; `identity`: the temporary's device and inode,
// named as the target.
void commitInto(const fs::path& temporary, const fs::path& target, Committed identity) {
  keepWhatIsThere(target, identity);
  try {
    renameInto(temporary, target);
  } catch (...) {
    dropBackup(identity);
    throw;
  }
  recordCommitted(identity);
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

// How long a write to a FIFO waits for a process to open it for reading (a reader started beside the
// command, `hairgen ... -o pipe & consumer < pipe`), before it fails rather than waiting for ever.
constexpr auto kFifoReaderWait = std::chrono::seconds(10);

// Opens a device or FIFO to write. A FIFO that no process opens to read within kFifoReaderWait is an
// IoError, not a wait for a reader that may never come; what is open is then written with blocking
// writes.
int openDirect(const fs::path& device, const fs::path& name) {
  struct stat st {};
  if (::stat(device.c_str(), &st) == 0 && S_ISSOCK(st.st_mode))
    throw IoError({name.string(), 0},
                  "cannot write: it is a socket; hairgen writes files, devices and FIFOs");
  const bool fifo = S_ISFIFO(st.st_mode);
  const auto giveUp = std::chrono::steady_clock::now() + kFifoReaderWait;
  int fd = -1;
  while ((fd = ::open(device.c_str(), O_WRONLY | O_NONBLOCK | O_CLOEXEC)) < 0 && errno == ENXIO && fifo &&
         std::chrono::steady_clock::now() < giveUp)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));  // ENXIO: a FIFO with no reader yet
  if (fd < 0) {
    if (errno == ENXIO && fifo)
      throw IoError({name.string(), 0},
                    "cannot write: it is a FIFO (a named pipe) that no process opened to read "
                    "within " +
                        std::to_string(kFifoReaderWait.count()) + " s");
    throw IoError({name.string(), 0}, std::string("cannot write: ") + std::strerror(errno));
  }
  const int flags = ::fcntl(fd, F_GETFL);
  if (flags == -1 || ::fcntl(fd, F_SETFL, flags & ~O_NONBLOCK) == -1) {
    const int error = errno;
    ::close(fd);
    throw IoError({name.string(), 0}, std::string("cannot write: ") + std::strerror(error));
  }
  return fd;
}

// Copies a finished file into a device or FIFO.
void copyInto(const fs::path& from, const fs::path& device) {
  const int fd = openDirect(device, device);
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

InputFile::InputFile(const fs::path& path, Reading reading) : name_(path.string()) {
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
  else if (reading == Reading::kWhole && uint64_t(st.st_size) > memoryBudget())
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

std::shared_ptr<FileMapping> InputFile::mapping() {
  if (!mapping_ && !mappingRefused_) {
    mapping_ = FileMapping::map(fd_, size_, name_);
    mappingRefused_ = !mapping_;
  }
  return mapping_;
}

void InputFile::skip(uint64_t bytes) {
  if (bytes > size_ - position_) throw InputError({name_, 0}, kFileShrank);
  if (::lseek(fd_, off_t(position_ + bytes), SEEK_SET) < 0)
    throw IoError({name_, 0}, std::string("seek failed: ") + std::strerror(errno));
  position_ += bytes;
}

void InputFile::read(void* out, size_t bytes) {
  if (bytes > size_ - position_) throw InputError({name_, 0}, kFileShrank);
  size_t done = 0;
  while (done < bytes) {
    const ssize_t n = ::read(fd_, static_cast<char*>(out) + done, bytes - done);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) throw IoError({name_, 0}, std::string("read failed: ") + std::strerror(errno));
    if (n == 0) throw InputError({name_, 0}, kFileShrank);
    done += size_t(n);
  }
  position_ += bytes;
}

void requireWritableOutput(const fs::path& target) {
  const Destination destination = destinationOf(target);  // a directory, a closed descriptor: refused
  if (destination.direct) return;
  constexpr size_t kLongestName = 255;  // a folder entry's bytes on Linux's file systems
  if (const size_t bytes = destination.path.filename().string().size(); bytes > kLongestName)
    throw InputError({target.string(), 0}, "its name is " + std::to_string(bytes) +
                                               " bytes long; a file's name holds at most " +
                                               std::to_string(kLongestName));
  // The deepest folder that exists on the way to the file's: the one a write creates folders in (or
  // renames in).
  const fs::path folder = walkFolders(destination.path, target.string(), false);
  if (::access(folder.c_str(), W_OK | X_OK) != 0)
    throw IoError({target.string(), 0},
                  std::string("cannot write in ") + folder.string() + ": " + std::strerror(errno));
}

void createOutputFolder(const fs::path& folder) {
  walkFolders(folder / "file", folder.string(), true);
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
  return formatDigest(mix(hash));
}

std::string readFileText(const fs::path& path) {
  return readWhole<std::string>(path);
}

std::vector<uint8_t> readFileBytes(const fs::path& path) {
  return readWhole<std::vector<uint8_t>>(path);
}

// The stream's bytes to a descriptor, in 64 KiB writes; a failed write leaves the stream bad and keeps
// its errno for the message.
class AtomicFile::Buffer : public std::streambuf {
 public:
  explicit Buffer(int fd) : fd_(fd), buffer_(size_t(1) << 16) {
    setp(buffer_.data(), buffer_.data() + buffer_.size());
  }
  int error() const { return error_; }

 protected:
  int_type overflow(int_type ch) override {
    if (!drain()) return traits_type::eof();
    if (!traits_type::eq_int_type(ch, traits_type::eof())) {
      *pptr() = traits_type::to_char_type(ch);
      pbump(1);
    }
    return traits_type::not_eof(ch);
  }
  int sync() override { return drain() ? 0 : -1; }
  std::streamsize xsputn(const char* data, std::streamsize size) override {
    if (size < std::streamsize(buffer_.size())) return std::streambuf::xsputn(data, size);
    // A large block goes to the descriptor as it is, after what is buffered.
    return drain() && writeAll(data, size_t(size)) ? size : 0;
  }

 private:
  bool drain() {
    const bool ok = writeAll(pbase(), size_t(pptr() - pbase()));
    setp(buffer_.data(), buffer_.data() + buffer_.size());
    return ok;
  }
  bool writeAll(const char* data, size_t size) {
    for (size_t done = 0; done < size;) {
      const ssize_t n = ::write(fd_, data + done, size - done);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) {
        error_ = n < 0 ? errno : ENOSPC;
        return false;
      }
      done += size_t(n);
    }
    return true;
  }

  int fd_;
  std::vector<char> buffer_;
  int error_ = 0;
};

AtomicFile::AtomicFile(fs::path target) : stream_(nullptr) {
  const Destination destination = destinationOf(target);
  target_ = destination.path;
  descriptor_ = destination.descriptor;
  if (destination.direct && descriptor_ < 0) {
    // A device or FIFO, written in place (it exists: nothing is created here).
    fd_ = openDirect(target_, target);
  } else {
    // A descriptor's file is written whole at the end, from a temporary in the system's folder.
    Temporary t =
        createTemporaryBeside(descriptor_ >= 0 ? fs::temp_directory_path() / target_.filename() : target_);
    temporary_ = t.path;
    fd_ = t.fd;
    slot_ = t.slot;
  }
  buffer_ = std::make_unique<Buffer>(fd_);
  stream_.rdbuf(buffer_.get());
}

AtomicFile::~AtomicFile() {
  if (fd_ >= 0) ::close(fd_);
  if (committed_) return;
  if (!temporary_.empty()) ::unlink(temporary_.c_str());  // the name this object created, never another
  releaseTemporary(slot_);
}

void AtomicFile::commit() {
  stream_.flush();
  int error = stream_ ? 0 : buffer_->error();
  const bool written = static_cast<bool>(stream_);
  const Committed identity = temporary_.empty() ? Committed{} : identityOf(fd_, target_);
  if (::close(fd_) != 0 && written) error = errno;  // NFS reports a full disk here
  fd_ = -1;
  if (!written || error != 0)
    throw IoError(
        {target_.string(), 0},
        std::string("write failed: ") + (error ? std::strerror(error) : "(no space left on the device?)"));
  if (descriptor_ >= 0) {
    copyToDescriptor(temporary_, descriptor_, target_);
    ::unlink(temporary_.c_str());
  } else if (!temporary_.empty()) {
    commitInto(temporary_, target_, identity);
  }
  releaseTemporary(slot_);
  committed_ = true;
}

void writeThroughTemporary(const fs::path& target, const std::function<void(const fs::path&)>& write) {
  const Destination destination = destinationOf(target);
  // A device's folder (/dev) is no place for a temporary: the system's temporary folder is.
  const Temporary temporary = createPrivateTemporary(
      destination.direct ? fs::temp_directory_path() / target.filename() : destination.path);
  ::close(temporary.fd);  // the library opens it by name, in this process's private folder
  try {
    write(temporary.path);
    if (destination.descriptor >= 0) {
      copyToDescriptor(temporary.path, destination.descriptor, destination.path);
    } else if (destination.direct) {
      copyInto(temporary.path, destination.path);
    } else {
      // The file the library left at the temporary's name (it may have made it anew) is what is
      // renamed, and what a cleanup may remove.
      struct stat st {};
      if (::lstat(temporary.path.c_str(), &st) != 0 || !S_ISREG(st.st_mode))
        throw IoError({target.string(), 0},
                      "write failed: the temporary " + temporary.path.string() + " is gone");
      commitInto(temporary.path, destination.path, committedAs(destination.path, st));
    }
  } catch (...) {
    releaseTemporary(temporary.slot);  // before its descriptor's number can be another's
    removePrivateTemporary(temporary);
    throw;
  }
  releaseTemporary(temporary.slot);
  removePrivateTemporary(temporary);  // the folder, now empty (the file was renamed or copied)
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
  // Newest first, each only while its name still holds the very file this process made there: never a
  // file that replaced it since, and never what a link there points to (unlink removes a link itself).
  // What the name held before is put back (rename: atomically, the name never missing); a name that
  // held a file that could not be kept keeps the new one, the only one there is.
  for (size_t i = gCommitted.size(); i > gKept; --i) {
    Committed& file = gCommitted[i - 1];
    struct stat st {};
    // The name holds this commit's file, or a later commit's of this process at the same name (one
    // that could keep no backup of this one's): either way this commit's backup is what was there.
    bool ours = false;
    if (::lstat(file.path.c_str(), &st) == 0 && S_ISREG(st.st_mode))
      for (size_t k = i - 1; k < gCommitted.size() && !ours; ++k)
        ours = gCommitted[k].path == file.path && st.st_dev == gCommitted[k].device &&
               st.st_ino == gCommitted[k].inode;
    if (ours && !file.backup.empty()) {
      // Put back; should the rename fail, the old file stays under the backup's name, never removed.
      ::rename(file.backup.c_str(), file.path.c_str());
      releaseTemporary(file.backupSlot);
      continue;
    }
    if (ours && !file.replaced) ::unlink(file.path.c_str());
    dropBackup(file);
  }
  gCommitted.resize(gKept);
}

void keepCommittedOutputs() {
  requireMappingsWhole();  // a frame made from a mapped input's unreadable page (zeros) is not kept
  std::lock_guard<std::mutex> lock(gCommittedMutex);
  for (size_t i = gKept; i < gCommitted.size(); ++i) dropBackup(gCommitted[i]);
  gKept = gCommitted.size();
}

std::vector<fs::path> committedOutputs() {
  std::lock_guard<std::mutex> lock(gCommittedMutex);
  std::vector<fs::path> paths;
  for (const Committed& file : gCommitted) paths.push_back(file.path);
  return paths;
}

void forgetCommittedOutputs() {
  std::lock_guard<std::mutex> lock(gCommittedMutex);
  for (Committed& file : gCommitted) dropBackup(file);
  gCommitted.clear();
  gKept = 0;
}

}  // namespace hairgen
