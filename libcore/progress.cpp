#include "libcore/progress.h"

#include <cstdio>

namespace hairgen {

Progress::Progress(std::string stage, std::string unit, size_t total, bool enabled)
    : stage_(std::move(stage)), unit_(std::move(unit)), total_(total), enabled_(enabled && total > 0),
      start_(std::chrono::steady_clock::now()) {}

void Progress::advance(size_t done) {
  if (!enabled_) return;
  size_t now = done_.fetch_add(done, std::memory_order_relaxed) + done;
  int tenth = static_cast<int>(10 * now / total_);
  if (tenth <= printedTenth_.load(std::memory_order_relaxed)) return;
  double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  if (seconds < 1.0) return;
  std::lock_guard lock(print_);
  if (tenth <= printedTenth_.load()) return;
  printedTenth_.store(tenth);
  std::fprintf(stderr, "%s: %3d%% (%zu of %zu %s, %.1f s)\n", stage_.c_str(), static_cast<int>(100 * now / total_), now,
               total_, unit_.c_str(), seconds);
}

}  // namespace hairgen
