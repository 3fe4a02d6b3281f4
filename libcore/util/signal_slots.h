// A fixed table that a signal handler reads while other threads fill it. Each slot is free, being
// filled, or live: a thread claims a free slot with a compare-and-swap (the handler passes it by while
// it is filled), makes it live, and frees it when done; the handler reads live slots only, with atomic
// loads and plain memory, which is async-signal-safe. No allocation: a full table says so (claim()
// gives −1) and the caller goes on without the handler's help. The interrupt cleanup's temporaries
// (file_util.cpp) and the mapping guard's mappings (mapped_file.cpp) are two such tables.
#pragma once

#include <array>
#include <atomic>
#include <cstddef>

namespace hairgen {

template <class Entry, size_t N>
class SignalSlots {
 public:
  // A free slot, now being filled, or −1 when every slot is taken.
  int claim() {
    for (size_t i = 0; i < N; ++i) {
      int expected = kFree;
      if (slots_[i].state.compare_exchange_strong(expected, kFilling)) return int(i);
    }
    return -1;
  }
  // A claimed slot's entry, to fill while it is being filled (and to read while it is live).
  Entry& operator[](int slot) { return slots_[size_t(slot)].entry; }
  // The handler reads the slot from now on; nothing for −1.
  void markLive(int slot) {
    if (slot >= 0) slots_[size_t(slot)].state.store(kLive);
  }
  // The slot is free again, and the handler passes it by; nothing for −1.
  void release(int slot) {
    if (slot >= 0) slots_[size_t(slot)].state.store(kFree);
  }
  // f(entry) for every live entry. Async-signal-safe where `f` is.
  template <class F>
  void forEachLive(F&& f) {
    for (Slot& s : slots_)
      if (s.state.load() == kLive) f(s.entry);
  }
  // The first live entry `matches`, or null. Async-signal-safe where `matches` is.
  template <class F>
  Entry* findLive(F&& matches) {
    for (Slot& s : slots_)
      if (s.state.load() == kLive && matches(s.entry)) return &s.entry;
    return nullptr;
  }

 private:
  enum : int { kFree, kFilling, kLive };
  struct Slot {
    std::atomic<int> state{kFree};
    Entry entry;
  };
  std::array<Slot, N> slots_;
};

}  // namespace hairgen
