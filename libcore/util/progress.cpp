#include "libcore/util/progress.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace hairgen {
namespace {

constexpr double kQuietFor = 1.0;   // seconds before anything is printed
constexpr double kBarEvery = 0.1;   // live bar refresh
constexpr double kLineEvery = 5.0;  // log line interval

}  // namespace

std::optional<double> estimatedSecondsLeft(size_t done, size_t total, double elapsed) {
  if (done == 0 || done >= total || !(elapsed >= 0.0)) return std::nullopt;
  const double fraction = double(done) / double(total);
  if (fraction < kEtaAfterFraction && elapsed < kEtaAfterSeconds) return std::nullopt;
  return elapsed * double(total - done) / double(done);
}

std::string formatDuration(double seconds) {
  const long long s = std::llround(std::max(seconds, 0.0));
  char text[48];
  if (s < 60)
    std::snprintf(text, sizeof text, "%lld s", s);
  else if (s < 3600)
    std::snprintf(text, sizeof text, "%lld min %02lld s", s / 60, s % 60);
  else
    std::snprintf(text, sizeof text, "%lld h %02lld min", s / 3600, s / 60 % 60);
  return text;
}

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
  const std::optional<double> left = estimatedSecondsLeft(done, total_, seconds);
  if (terminal_) {
    constexpr int kWidth = 30;
    std::string bar(kWidth * percent / 100, '#');
    bar.resize(kWidth, ' ');
    // Padded, so a shorter estimate overwrites the end of a longer one.
    const std::string eta = left ? ", about " + formatDuration(*left) + " left" : "";
    std::fprintf(stderr, "\r%s [%s] %3d%% %zu/%zu %s %.1f s%-26s", stage_.c_str(), bar.c_str(), percent, done,
                 total_, unit_.c_str(), seconds, eta.c_str());
  } else {
    const std::string eta = left ? ", about " + formatDuration(*left) + " left" : "";
    std::fprintf(stderr, "%s: %3d%% (%zu of %zu %s, %.1f s%s)\n", stage_.c_str(), percent, done, total_,
                 unit_.c_str(), seconds, eta.c_str());
  }
  std::fflush(stderr);
  printed_ = true;
}

}  // namespace hairgen
