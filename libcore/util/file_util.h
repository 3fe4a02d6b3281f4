// Reading inputs whole and writing outputs all or nothing (DESIGN §2).
//
// Inputs: only regular files are read (a FIFO, device or directory named as an input is refused before
// it is opened, so nothing waits on a pipe), and a file larger than the memory budget is refused.
//
// Outputs: a regular file (or a new name) is written to a temporary beside it, NAME.tmp-HOST-PID-N (NAME
// cut so the whole fits a folder entry), that this process creates itself (O_CREAT | O_EXCL |
// O_NOFOLLOW: never a name someone put there), and renamed over the name on commit. A library that opens
// its file by name (OpenEXR, ffmpeg, OpenVDB) gets one in a private folder of that name instead (mode
// 0700), so no one can swap it for a link before the library opens it. A symbolic link named as an
// output is replaced by the file, as mv replaces it: nothing is written through the link into the file
// it points to, and no folder is made for a link that points nowhere. Folders on the way are made as
// needed, one by one, but never through a dangling link: requireWritableOutput refuses one before the
// work (an InputError, exit 2), as it refuses a name longer than a folder entry holds; a write that
// finds one fails (an IoError, exit 1), as it does where something on the way is not a folder. A device,
// FIFO or socket (`--stats /dev/stdout`, a pipe), reached directly or through links, is written directly
// and never replaced; a FIFO that no process opens to read within 10 s is an IoError, not a wait for
// ever. A directory is refused. Write errors (a full disk, /dev/full) are IoErrors (exit 1).
//
// Interruptions and failures: installInterruptCleanup() makes SIGINT, SIGTERM and SIGHUP remove the
// temporaries of writes in flight and end the process with 128 + the signal; a later write beside the
// same target removes temporaries (regular files, private folders) that dead processes of this host
// left. A commit that replaces a file (or a link) keeps what was there as a hard link beside it, under a
// temporary's name, until the command keeps its outputs or fails. A command that fails calls
// discardCommittedOutputs(), which undoes the commits since the last keepCommittedOutputs(): a new name
// is removed, a replaced one gets back what it held (renamed back: the name is never missing); each only
// while its name still holds the file this process made there (checked by device and inode), so a
// cleanup never removes a file it did not make, and a failed command never costs a file that was there
// (its own input, written over in place).
#pragma once

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <ostream>
#include <string>
#include <vector>

#include "libcore/util/mapped_file.h"

namespace hairgen {

// Reads a whole input file. A missing, unreadable, non-regular or too large file is an InputError
// naming it (exit 2): the files hairgen reads are its inputs.
std::string readFileText(const std::filesystem::path& path);
std::vector<uint8_t> readFileBytes(const std::filesystem::path& path);

// An input read piece by piece, with readFileBytes' rules checked when it is opened (a regular file
// no larger than the memory budget, else an InputError naming it). read() fills exactly `bytes` bytes
// or throws: a file that ends early (kFileShrank) is an InputError, a read error an
// IoError.
class InputFile {
 public:
  // kWhole: the file is to be read whole, so one larger than the memory budget is refused; kParts: a
  // reader takes a few parts of it (a header), which a file of any size allows.
  enum class Reading { kWhole, kParts };
  explicit InputFile(const std::filesystem::path& path, Reading reading = Reading::kWhole);
  ~InputFile();
  InputFile(const InputFile&) = delete;
  InputFile& operator=(const InputFile&) = delete;

  uint64_t size() const { return size_; }
  uint64_t position() const { return position_; }
  uint64_t remaining() const { return size_ - position_; }
  void read(void* out, size_t bytes);
  // Moves on `bytes` without reading them (what remains is checked, as read() checks it).
  void skip(uint64_t bytes);
  // The whole file mapped (mapped_file.h), made on the first call; null where it cannot be.
  std::shared_ptr<FileMapping> mapping();

 private:
  std::string name_;
  int fd_ = -1;
  uint64_t size_ = 0, position_ = 0;
  std::shared_ptr<FileMapping> mapping_;
  bool mappingRefused_ = false;
};

// A 64-bit digest of a file's bytes, 16 hex digits (XXH64's round over little-endian 8-byte words in
// four interleaved lanes, then the size and MurmurHash3's finaliser: a flipped bit anywhere changes
// every bit of the result); "" where the file cannot be read as a regular file. The same bytes give
// the same digest on every machine, whatever its memory or byte order.
std::string contentDigest(const std::filesystem::path& path);

// Before the work: whether an output could be written where it is named. A directory there is an
// InputError (exit 2); a folder this process cannot write into (nor create, for one that does not exist
// yet) an IoError (exit 1), as the write itself would be, minutes later. Devices, FIFOs and the
// command's own descriptors pass.
void requireWritableOutput(const std::filesystem::path& target);

// Makes `folder` and the folders above it that are missing, as an output's folders are made: never
// through a dangling symbolic link. Throws InputError when something on the way is not a folder or is a
// link to nothing, IoError when a folder cannot be made.
void createOutputFolder(const std::filesystem::path& folder);

// For inputs a library opens by name: an InputError unless `path` is a regular file.
void requireRegularFile(const std::filesystem::path& path);

class AtomicFile {
 public:
  explicit AtomicFile(std::filesystem::path target);
  ~AtomicFile();  // an uncommitted file's temporary is removed
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  std::ostream& stream() { return stream_; }
  // Flushes, checks for write errors and renames into place. Throws IoError on failure.
  void commit();

 private:
  class Buffer;                      // the stream's bytes to fd_
  std::filesystem::path target_;     // the name written (a link there is replaced, not followed)
  std::filesystem::path temporary_;  // empty when writing a device or FIFO directly
  int descriptor_ = -1;  // an open descriptor of this process the file goes to (/dev/stdout), or -1
  int fd_ = -1;          // what the stream writes to: the temporary this object created, or the device
  int slot_ = -1;        // the temporary's entry in the interrupt cleanup table
  std::unique_ptr<Buffer> buffer_;
  std::ostream stream_;
  bool committed_ = false;
};

// Writes `target` through a file that `write` fills by name (for libraries that want a path, such as
// OpenEXR and OpenImageIO), with the same rules as AtomicFile: renamed into place when `write` returns,
// removed when it throws; for a device or FIFO the file's bytes are copied into it.
void writeThroughTemporary(const std::filesystem::path& target,
                           const std::function<void(const std::filesystem::path&)>& write);

// Convenience: AtomicFile with one write.
void writeFileAtomic(const std::filesystem::path& target, const void* data, size_t size);
inline void writeFileAtomic(const std::filesystem::path& target, const std::string& text) {
  writeFileAtomic(target, text.data(), text.size());
}

// Installs the SIGINT, SIGTERM and SIGHUP handlers (once; a signal the parent set to be ignored stays
// ignored).
void installInterruptCleanup();

// discardCommittedOutputs: undoes the commits since the last keepCommittedOutputs() (or since
// forgetCommittedOutputs()), each only while its name still holds the file this process made there
// (a failed command's outputs): a new name is removed, a replaced one gets back what it held.
// keepCommittedOutputs: the files committed so far are finished and stay whatever happens later (a sequence's
// frames: a failed frame never costs the frames before it), unless a mapped input's page could not be read
// since the last check: then it keeps none and throws requireMappingsWhole()'s error (mapped_file.h), for
// what was made from its zeros. forgetCommittedOutputs: forgets every file (a command that succeeded, or one
// that starts).
void discardCommittedOutputs();
void keepCommittedOutputs();
void forgetCommittedOutputs();
// The files committed and not discarded since forgetCommittedOutputs, in commit order (for --stats).
std::vector<std::filesystem::path> committedOutputs();

}  // namespace hairgen
