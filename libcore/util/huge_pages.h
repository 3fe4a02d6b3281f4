// Large fresh arrays faulted in on transparent huge pages, on every core. A fresh array of 115 MB is
// ~28,000 pages of 4 KiB that the kernel faults in one at a time as the array is first written (~2 µs
// each: the fault, clearing the page, charging it to the process), all on the thread that writes it
// (std::vector's resize, one thread). On pages of 2 MiB it is ~60 faults and the clearing alone, and
// faulted in ahead from every core the clearing is shared out. Linux's madvise(MADV_HUGEPAGE), honoured
// when /sys/kernel/mm/transparent_hugepage/enabled is "madvise" (Debian's and Ubuntu's default) or
// "always", and MADV_POPULATE_WRITE (Linux 5.14); elsewhere, and for arrays smaller than a huge page, it
// does nothing. Contents and results are never affected, only where the memory comes from and when.
#pragma once

#include <cstddef>
#include <vector>

namespace hairgen {

// Asks for huge pages under the whole pages of [data, data + bytes) and faults them in now, in
// parallel; the bytes are not written. Refusals are not errors: the pages then fault in as before.
void faultInHugePages(const void* data, size_t bytes);

// v.resize(n); when v must grow, its new storage is faulted in by faultInHugePages before the resize
// writes it (the elements v holds are copied over, as a growing vector copies them).
template <class T>
void resizeOnHugePages(std::vector<T>& v, size_t n) {
  if (n > v.capacity()) {
    std::vector<T> grown;
    grown.reserve(n);
    faultInHugePages(grown.data(), n * sizeof(T));
    grown.insert(grown.end(), v.begin(), v.end());
    v.swap(grown);
  }
  v.resize(n);
}

}  // namespace hairgen
