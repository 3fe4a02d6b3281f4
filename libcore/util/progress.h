// Progress of long work on stderr (DESIGN §3): a live bar on a terminal, otherwise a line every few
// seconds for farm logs, with the time left once it can be estimated. Nothing is printed in the first
// second, so short runs stay quiet. Safe to advance from many threads; what it prints never affects
// results.
#pragma once

#include <atomic>
#include <chrono>
#include <cstddef>
#include <mutex>
#include <optional>
#include <string>

namespace hairgen {

// The estimated seconds left when `done` of `total` units took `elapsed` seconds, at the rate so far:
// none before kEtaAfterFraction of the work or kEtaAfterSeconds have passed (too little to judge the
// rate by), nor once it is all done.
inline constexpr double kEtaAfterFraction = 0.05;
inline constexpr double kEtaAfterSeconds = 2.0;
std::optional<double> estimatedSecondsLeft(size_t done, size_t total, double elapsed);

// A duration as a person reads it: "42 s", "3 min 05 s", "2 h 07 min".
std::string formatDuration(double seconds);

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
