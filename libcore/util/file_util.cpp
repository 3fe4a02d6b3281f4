#include "libcore/util/file_util.h"

#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <system_error>

#include "libcore/util/error.h"

namespace hairgen {
namespace {

template <typename Container>
Container readWhole(const std::filesystem::path& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec))
    throw InputError({path.string(), 0}, "is a directory, expected a file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError({path.string(), 0}, std::string("cannot open: ") + std::strerror(errno));
  in.seekg(0, std::ios::end);
  std::streamoff size = in.tellg();
  if (size < 0) throw InputError({path.string(), 0}, "cannot determine the file size");
  in.seekg(0, std::ios::beg);
  Container data(static_cast<size_t>(size), 0);
  if (size > 0 && !in.read(reinterpret_cast<char*>(data.data()), size))
    throw IoError({path.string(), 0}, "read failed");
  return data;
}

// A fresh name beside `target` (its folder created): TARGET.tmp-PID-N.
std::filesystem::path temporaryBeside(const std::filesystem::path& target) {
  static std::atomic<unsigned> counter{0};
  std::filesystem::path dir = target.parent_path();
  if (!dir.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(dir, ec);
    if (ec) throw IoError({dir.string(), 0}, "cannot create directory: " + ec.message());
  }
  std::filesystem::path temporary = target;
  temporary += ".tmp-" + std::to_string(::getpid()) + "-" + std::to_string(counter++);
  return temporary;
}

void renameInto(const std::filesystem::path& temporary, const std::filesystem::path& target) {
  std::error_code ec;
  std::filesystem::rename(temporary, target, ec);
  if (ec) throw IoError({target.string(), 0}, "cannot rename into place: " + ec.message());
}

}  // namespace

std::string readFileText(const std::filesystem::path& path) {
  return readWhole<std::string>(path);
}

std::vector<uint8_t> readFileBytes(const std::filesystem::path& path) {
  return readWhole<std::vector<uint8_t>>(path);
}

void writeThroughTemporary(const std::filesystem::path& target,
                           const std::function<void(const std::filesystem::path&)>& write) {
  const std::filesystem::path temporary = temporaryBeside(target);
  try {
    write(temporary);
    renameInto(temporary, target);
  } catch (...) {
    std::error_code ec;
    std::filesystem::remove(temporary, ec);
    throw;
  }
}

AtomicFile::AtomicFile(std::filesystem::path target) : target_(std::move(target)) {
  temporary_ = temporaryBeside(target_);
  stream_.open(temporary_, std::ios::binary | std::ios::trunc);
  if (!stream_) throw IoError({target_.string(), 0}, std::string("cannot write: ") + std::strerror(errno));
}

AtomicFile::~AtomicFile() {
  if (committed_) return;
  stream_.close();
  std::error_code ec;
  std::filesystem::remove(temporary_, ec);
}

void AtomicFile::commit() {
  stream_.flush();
  bool ok = static_cast<bool>(stream_);
  stream_.close();
  if (!ok || stream_.fail()) throw IoError({target_.string(), 0}, "write failed (disk full?)");
  renameInto(temporary_, target_);
  committed_ = true;
}

void writeFileAtomic(const std::filesystem::path& target, const void* data, size_t size) {
  AtomicFile file(target);
  file.stream().write(static_cast<const char*>(data), static_cast<std::streamsize>(size));
  file.commit();
}

}  // namespace hairgen
