// Progress of long work on stderr, for people watching and for farm logs: a line per tenth of the
// work, and only once the work has run for a second, so short runs stay quiet. Safe to advance from
// many threads; what it prints never affects results.
#pragma once

#include <atomic>
#include <chrono>
#include <cstddef>
#include <mutex>
#include <string>

namespace hairgen {

class Progress {
 public:
  // `what` names the stage and the unit, e.g. "grow" and "guides". A disabled one prints nothing.
  Progress(std::string stage, std::string unit, size_t total, bool enabled);
  void advance(size_t done = 1);

 private:
  std::string stage_, unit_;
  size_t total_;
  bool enabled_;
  std::chrono::steady_clock::time_point start_;
  std::atomic<size_t> done_{0};
  std::atomic<int> printedTenth_{0};
  std::mutex print_;
};

}  // namespace hairgen
