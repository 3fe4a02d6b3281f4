#include "libcore/util/huge_pages.h"

#include <algorithm>
#include <cstdint>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#if defined(__linux__)
#include <sys/mman.h>
#include <unistd.h>
#endif

namespace hairgen {

void faultInHugePages(const void* data, size_t bytes) {
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  constexpr uintptr_t kHugePage = uintptr_t(2) << 20;  // bytes, x86-64's and most arm64 kernels'
  if (bytes < kHugePage) return;
  const uintptr_t page = uintptr_t(sysconf(_SC_PAGESIZE));
  const uintptr_t first = (uintptr_t(data) + page - 1) / page * page,
                  end = (uintptr_t(data) + bytes) / page * page;
  if (end <= first) return;
  // Advice only: a kernel without transparent huge pages refuses it, and the small pages serve as before.
  madvise(reinterpret_cast<void*>(first), end - first, MADV_HUGEPAGE);
#if defined(MADV_POPULATE_WRITE)
  // Faults in and clears the pages a huge page at a time, the huge pages shared among the threads. An
  // older kernel refuses it and the pages fault in when first written.
  const size_t chunks = (end - first + kHugePage - 1) / kHugePage;
  tbb::parallel_for(tbb::blocked_range<size_t>(0, chunks, 4), [&](const tbb::blocked_range<size_t>& r) {
    const uintptr_t from = first + r.begin() * kHugePage, to = std::min(end, first + r.end() * kHugePage);
    madvise(reinterpret_cast<void*>(from), to - from, MADV_POPULATE_WRITE);
  });
#endif
#else
  (void)data;
  (void)bytes;
#endif
}

}  // namespace hairgen
