// The lowest of values offered from many threads: how a parallel loop finds the first strand (or block)
// in index order that fails a check, whatever the threads and their order, so the error it reports is
// the one a single thread would.
#pragma once

#include <atomic>

namespace hairgen {

// Lowers `lowest` to `candidate` when `candidate` is smaller; safe from any number of threads at once.
template <typename T>
void atomicMin(std::atomic<T>& lowest, T candidate) {
  T seen = lowest.load();
  while (candidate < seen && !lowest.compare_exchange_weak(seen, candidate)) {
  }
}

}  // namespace hairgen
