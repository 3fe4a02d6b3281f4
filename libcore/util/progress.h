// Progress of long work on stderr (DESIGN §3): a live bar on a terminal, otherwise a line every few
// seconds for farm logs. Nothing is printed in the first second, so short runs stay quiet. Safe to
// advance from many threads; what it prints never affects results.
#pragma once

#include <atomic>
#include <chrono>
#include <cstddef>
#include <mutex>
#include <string>

namespace hairgen {

class Progress {
 public:
  // `stage` and `unit` name the work, e.g. "grow" and "guides". A disabled one prints nothing.
  Progress(std::string stage, std::string unit, size_t total, bool enabled);
  ~Progress() { finish(); }
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  void advance(size_t done = 1);
  // Ends a live bar's line (at its final count); later calls do nothing.
  void finish();

 private:
  using Clock = std::chrono::steady_clock;
  void print(size_t done, double seconds);

  std::string stage_, unit_;
  size_t total_;
  std::atomic<bool> enabled_;
  bool terminal_;
  Clock::time_point start_;
  std::atomic<size_t> done_{0};
  std::atomic<double> nextPrint_;  // seconds since start
  std::mutex print_;
  bool printed_ = false;
};

}  // namespace hairgen
