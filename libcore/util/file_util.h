// Whole-file reading and all-or-nothing writing.
#pragma once

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

namespace hairgen {

// Reads a whole file. A missing or unreadable file is an InputError naming it (exit 2): the files
// hairgen reads are its inputs.
std::string readFileText(const std::filesystem::path& path);
std::vector<uint8_t> readFileBytes(const std::filesystem::path& path);

// Writes to a temporary file beside `target` and renames it over the target on commit(), so a failed
// or interrupted command leaves no partial output (DESIGN §2). Destroying an uncommitted AtomicFile
// removes the temporary.
class AtomicFile {
 public:
  explicit AtomicFile(std::filesystem::path target);
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  std::ostream& stream() { return stream_; }
  // Flushes, checks for write errors and renames into place. Throws IoError on failure.
  void commit();

 private:
  std::filesystem::path target_;
  std::filesystem::path temporary_;
  std::ofstream stream_;
  bool committed_ = false;
};

// Writes `target` through a temporary file beside it that `write` fills by name (for libraries that
// want a path, such as OpenEXR and OpenImageIO): renamed into place when `write` returns, removed
// when it throws. Throws IoError when the rename fails.
void writeThroughTemporary(const std::filesystem::path& target,
                           const std::function<void(const std::filesystem::path&)>& write);

// Convenience: AtomicFile with one write.
void writeFileAtomic(const std::filesystem::path& target, const void* data, size_t size);
inline void writeFileAtomic(const std::filesystem::path& target, const std::string& text) {
  writeFileAtomic(target, text.data(), text.size());
}

}  // namespace hairgen
