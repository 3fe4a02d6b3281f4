// Large arrays made fast to first touch: for hundreds of MB (a coupe's points and tangents), faulting
// in 4 KiB pages one at a time on one thread took longer than filling them.
#pragma once

#include <sys/mman.h>

#include <cstddef>
#include <cstdint>
#include <type_traits>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace hairgen {

constexpr size_t kHugePage = size_t(2) << 20;  // bytes, x86-64's transparent huge page

// Asks the kernel to back the whole 2 MiB pages within [data, data + bytes) with huge pages (madvise;
// only advice: where transparent huge pages are off, or the memory is a device's, nothing changes).
inline void adviseHugePages(void* data, size_t bytes) {
  constexpr uintptr_t kHuge = kHugePage;
  const uintptr_t begin = (reinterpret_cast<uintptr_t>(data) + kHuge - 1) & ~(kHuge - 1);
  const uintptr_t end = (reinterpret_cast<uintptr_t>(data) + bytes) & ~(kHuge - 1);
  if (end > begin) madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE);
}

// v resized to n. When it grows past 8 MiB, its new storage is asked of the kernel in 2 MiB pages
// (madvise; only advice: where transparent huge pages are off, it has 4 KiB ones) and faulted in by
// every core at once before resize makes the elements. The values are resize's: the old ones kept,
// new ones as the allocator makes them (zeros for std::allocator, unset for UninitialisedAllocator).
// `spare`: elements more that new storage holds, untouched (address space, not memory, until used), for
// storage handed on to be reused for a little more.
template <class T, class A>
void resizeLarge(std::vector<T, A>& v, size_t n, size_t spare = 0) {
  static_assert(std::is_trivially_copyable_v<T>, "its storage is touched before it holds elements");
  constexpr size_t kLarge = size_t(8) << 20;
  if (n > v.capacity() && n * sizeof(T) >= kLarge) {
    std::vector<T, A> fresh;
    fresh.reserve(n + spare);
    adviseHugePages(fresh.data(), (n + spare) * sizeof(T));
    // A zero byte in every 4 KiB page of the storage not yet holding elements: its faults (the kernel
    // clears each page) on every core. This writes past size() into reserved storage, which holds no
    // objects yet: fine for a trivially copyable T, whose bytes assign and resize then write whole (a
    // checked vector, as _GLIBCXX_SANITIZE_VECTOR makes, would call it an overflow).
    volatile unsigned char* bytes = reinterpret_cast<unsigned char*>(fresh.data());
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n * sizeof(T), kHugePage),
                      [&](const tbb::blocked_range<size_t>& r) {
                        for (size_t b = r.begin(); b < r.end(); b += 4096) bytes[b] = 0;
                      });
    fresh.assign(v.begin(), v.end());
    v.swap(fresh);
  }
  v.resize(n);
}

}  // namespace hairgen
