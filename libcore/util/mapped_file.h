// Large arrays read where a file's pages lie (mmap), not copied into fresh memory: a 1080p render of a
// 242 MB coupe spent a tenth of its CPU time having the kernel clear the pages its points and tangents
// were copied into, and held its tangents through the passes that never read them (docs/performance.md).
//
// A mapping is private and copy-on-write: an array in it reads the file's bytes, and a write changes
// the process's copy of that page only, never the file. Another process that rewrites the file in
// place while it is mapped (cp over it; hairgen's own writes rename a new file into place) changes
// what the pages this one has not written read. A page that cannot be read (the file shrank past it, or
// the disk or the network failed) raises SIGBUS: installMappingGuard()'s handler turns that mapping's
// pages into zeros, so the work goes on without crashing, and requireMappingsWhole() then fails the
// command with the file's error before it writes anything made from them.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <type_traits>
#include <utility>

#include "libcore/util/uninitialised.h"

namespace hairgen {

// What a read of a file that ends early says (InputFile::read, and a mapping's page past the end).
inline constexpr char kFileShrank[] = "the file shrank while it was read";
// What a mapping's page that could not be read says where the file is no shorter now: another process
// truncated and rewrote it (cp over it), or the disk or the network failed.
inline constexpr char kPageUnreadable[] =
    "a page of it could not be read while it was mapped: another process truncated or rewrote it, or the "
    "disk or network failed";

// A regular file's bytes, mapped private and writable (copy-on-write), unmapped with the last owner.
class FileMapping {
 public:
  // The open file `fd` of `size` bytes, named `name` in the error a page that cannot be read gives;
  // null where the kernel refuses to map it (a file system without mmap, no address space) or size is
  // 0: read it instead.
  static std::shared_ptr<FileMapping> map(int fd, uint64_t size, const std::string& name);
  ~FileMapping();
  FileMapping(const FileMapping&) = delete;
  FileMapping& operator=(const FileMapping&) = delete;

  uint8_t* data() const { return data_; }
  uint64_t size() const { return size_; }
  // The whole pages of [offset, offset + bytes) leave the process (madvise MADV_DONTNEED): read again,
  // they are mapped from the file anew. Only for pages nothing has written: a written page is the
  // process's copy, which this would drop for the file's bytes.
  void release(uint64_t offset, uint64_t bytes) const;

 private:
  FileMapping(uint8_t* data, uint64_t size, int guardSlot)
      : data_(data), size_(size), guardSlot_(guardSlot) {}
  uint8_t* data_;
  uint64_t size_;
  int guardSlot_;  // the guard's table slot, −1 when it was full (a fault is then the default SIGBUS)
};

// Part of a mapping that an array's storage may be (MappableAllocator): taken by the one allocation of
// exactly its size.
struct MappedRegion {
  std::shared_ptr<FileMapping> file;
  void* data = nullptr;
  size_t bytes = 0;
  size_t elementBytes = 0;  // the array's element's size: only an allocator of that size adopts it
  bool taken = false;
};

// An allocator for arrays of trivial values written whole after they are sized (a new element with no
// value given is left unset, as UninitialisedAllocator leaves it), whose storage may instead be a region
// of a mapped file: a vector made with MappableAllocator(region) and sized to the region's bytes holds
// the file's values without a copy, and keeps the mapping while it holds them. A copy of the vector
// gets storage of its own; a move, or a swap, takes the region along.
template <class T>
class MappableAllocator : public LeavesNewElementsUnset {
 public:
  static_assert(std::is_trivially_copyable_v<T> && std::is_trivially_default_constructible_v<T>);
  using value_type = T;
  using propagate_on_container_copy_assignment = std::false_type;
  using propagate_on_container_move_assignment = std::true_type;
  using propagate_on_container_swap = std::true_type;
  using is_always_equal = std::false_type;

  MappableAllocator() = default;
  explicit MappableAllocator(std::shared_ptr<MappedRegion> region) : region_(std::move(region)) {}
  // A moved allocator stays equal to what it was (the allocator requirements): moves copy (with the
  // copies declared, no move is).
  MappableAllocator(const MappableAllocator&) = default;
  MappableAllocator& operator=(const MappableAllocator&) = default;
  // Rebound to another type, it compares equal and adopts the region only for elements of its size.
  template <class U>
  MappableAllocator(const MappableAllocator<U>& other) noexcept : region_(other.region_) {}

  T* allocate(size_t n) {
    if (region_ && !region_->taken && region_->elementBytes == sizeof(T) && n * sizeof(T) == region_->bytes &&
        reinterpret_cast<uintptr_t>(region_->data) % alignof(T) == 0) {
      region_->taken = true;
      return static_cast<T*>(region_->data);
    }
    return std::allocator<T>().allocate(n);
  }
  void deallocate(T* p, size_t n) {
    if (region_ && p == region_->data) {
      region_.reset();  // this owner's hold on the mapping
      return;
    }
    std::allocator<T>().deallocate(p, n);
  }
  MappableAllocator select_on_container_copy_construction() const { return {}; }
  // Whether its vector's storage is a mapped file's region (a copy of the allocator says so too).
  bool holdsMapping() const { return region_ && region_->taken; }

  template <class U>
  friend bool operator==(const MappableAllocator& a, const MappableAllocator<U>& b) {
    return a.region_ == b.region_;
  }

 private:
  template <class>
  friend class MappableAllocator;
  std::shared_ptr<MappedRegion> region_;
};

// Installs the SIGBUS handler (once). A fault in one of hairgen's mappings (a page that cannot be read:
// the file shrank, or an I/O error) records it, makes that mapping's pages zeros and lets the work go
// on; a SIGBUS anywhere else, or one sent by kill, gets the default action.
void installMappingGuard();

// Throws, once, for a mapping whose page could not be read since the last call: InputError (exit 2,
// kFileShrank) where the file is now shorter than it was mapped, else IoError (exit 1,
// kPageUnreadable), naming the file. Called before anything made from mapped arrays is written, and by
// a failing command, whose error this one replaces.
void requireMappingsWhole();

}  // namespace hairgen
