// Wall-clock laps for --stats timings, shared by the stages, the renderer and the commands.
#pragma once

#include <chrono>

namespace hairgen {

// Seconds since construction or the last lap.
class Stopwatch {
 public:
  double lap() {
    auto now = std::chrono::steady_clock::now();
    double s = std::chrono::duration<double>(now - last_).count();
    last_ = now;
    return s;
  }

 private:
  std::chrono::steady_clock::time_point last_ = std::chrono::steady_clock::now();
};

}  // namespace hairgen
