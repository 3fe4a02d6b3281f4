#include "libcore/util/progress.h"

#include <unistd.h>

#include <cstdio>

namespace hairgen {
namespace {

constexpr double kQuietFor = 1.0;   // seconds before anything is printed
constexpr double kBarEvery = 0.1;   // live bar refresh
constexpr double kLineEvery = 5.0;  // log line interval

}  // namespace

Progress::Progress(std::string stage, std::string unit, size_t total, bool enabled)
    : stage_(std::move(stage)),
      unit_(std::move(unit)),
      total_(total),
      enabled_(enabled && total > 0),
      terminal_(isatty(STDERR_FILENO) != 0),
      start_(Clock::now()),
      nextPrint_(kQuietFor) {}

void Progress::finish() {
  std::lock_guard lock(print_);
  if (!enabled_ || !printed_ || !terminal_) return;
  print(done_.load(), std::chrono::duration<double>(Clock::now() - start_).count());
  std::fputc('\n', stderr);
  enabled_ = false;
}

void Progress::advance(size_t done) {
  if (!enabled_) return;
  size_t now = done_.fetch_add(done, std::memory_order_relaxed) + done;
  double seconds = std::chrono::duration<double>(Clock::now() - start_).count();
  if (seconds < nextPrint_.load(std::memory_order_relaxed)) return;
  std::unique_lock lock(print_, std::try_to_lock);
  if (!lock.owns_lock() || seconds < nextPrint_.load()) return;
  nextPrint_.store(seconds + (terminal_ ? kBarEvery : kLineEvery));
  print(now, seconds);
}

void Progress::print(size_t done, double seconds) {
  int percent = static_cast<int>(100 * std::min(done, total_) / total_);
  if (terminal_) {
    constexpr int kWidth = 30;
    std::string bar(kWidth * percent / 100, '#');
    bar.resize(kWidth, ' ');
    std::fprintf(stderr, "\r%s [%s] %3d%% %zu/%zu %s %.1f s", stage_.c_str(), bar.c_str(), percent, done,
                 total_, unit_.c_str(), seconds);
  } else {
    std::fprintf(stderr, "%s: %3d%% (%zu of %zu %s, %.1f s)\n", stage_.c_str(), percent, done, total_,
                 unit_.c_str(), seconds);
  }
  std::fflush(stderr);
  printed_ = true;
}

}  // namespace hairgen
