// Large arrays read where a file's pages lie (mmap), not copied into fresh memory: a 1080p render of a
// 242 MB coupe spent a tenth of its CPU time having the kernel clear the pages its points and tangents
// were copied into, and held its tangents through the passes that never read them (docs/performance.md).
//
// A mapping is private and copy-on-write: an array in it reads the file's bytes, and a write changes
// the process's copy of that page only, never the file. Another process that rewrites the file in
// place while it is mapped (cp over it; hairgen's own writes rename a new file into place and never do)
// changes what the pages it has not written read; one that shrinks it makes a read past its new end
// raise SIGBUS, which installMappingGuard() turns into the error a read would give ("the file shrank
// while it was read", exit 2).
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <new>
#include <string>
#include <type_traits>
#include <utility>

namespace hairgen {

// A regular file's bytes, mapped private and writable (copy-on-write), unmapped with the last owner.
class FileMapping {
 public:
  // The open file `fd` of `size` bytes (named `name` in the error a shrinking file gives); null where
  // the kernel refuses to map it (a file system without mmap) or size is 0: read it instead.
  static std::shared_ptr<FileMapping> map(int fd, uint64_t size, const std::string& name);
  ~FileMapping();
  FileMapping(const FileMapping&) = delete;
  FileMapping& operator=(const FileMapping&) = delete;

  uint8_t* data() const { return data_; }
  uint64_t size() const { return size_; }
  // The whole pages of [offset, offset + bytes) leave the process (madvise MADV_DONTNEED): read again,
  // they are mapped from the file anew. Only for pages nothing has written: a page written is the
  // process's copy, and would read the file's bytes again.
  void release(uint64_t offset, uint64_t bytes) const;

 private:
  FileMapping(uint8_t* data, uint64_t size, int guardSlot)
      : data_(data), size_(size), guardSlot_(guardSlot) {}
  uint8_t* data_;
  uint64_t size_;
  int guardSlot_;  // the guard's table slot (installMappingGuard), −1 when it was full
};

// Part of a mapping that an array's storage may be (MappableAllocator): taken by the one allocation of
// exactly its size.
struct MappedRegion {
  std::shared_ptr<FileMapping> file;
  void* data = nullptr;
  size_t bytes = 0;
  bool taken = false;
};

// An allocator for arrays of trivial values written whole after they are sized (a new element with no
// value given is left unset, as UninitialisedAllocator leaves it), whose storage may instead be a region
// of a mapped file: a vector made with MappableAllocator(region) and sized to the region's bytes holds
// the file's values without a copy, and keeps the mapping while it holds them. A copy of the vector
// gets storage of its own; a move, or a swap, takes the region along.
template <class T>
class MappableAllocator {
 public:
  static_assert(std::is_trivially_copyable_v<T> && std::is_trivially_default_constructible_v<T>);
  using value_type = T;
  using propagate_on_container_copy_assignment = std::false_type;
  using propagate_on_container_move_assignment = std::true_type;
  using propagate_on_container_swap = std::true_type;
  using is_always_equal = std::false_type;

  MappableAllocator() = default;
  explicit MappableAllocator(std::shared_ptr<MappedRegion> region) : region_(std::move(region)) {}
  template <class U>
  MappableAllocator(const MappableAllocator<U>& other) noexcept : region_(other.region_) {}

  T* allocate(size_t n) {
    if (region_ && !region_->taken && n * sizeof(T) == region_->bytes &&
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

  template <class U>
  void construct(U* p) noexcept {
    ::new (static_cast<void*>(p)) U;
  }
  template <class U, class... Args>
  void construct(U* p, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }

  template <class U>
  bool operator==(const MappableAllocator<U>& other) const {
    return region_ == other.region_;
  }

 private:
  template <class>
  friend class MappableAllocator;
  std::shared_ptr<MappedRegion> region_;
};

// Installs the SIGBUS handler (once): a read of a mapping past its file's end (the file shrank) removes
// the temporaries of writes in flight, says so in one line ("hairgen COMMAND: error: FILE: the file
// shrank while it was read") and ends the process with exit code 2; a SIGBUS anywhere else is left to
// the default action. `command`: the subcommand named in the line.
void installMappingGuard(const std::string& command);

}  // namespace hairgen
