#include "libcore/util/resources.h"

#include <sys/resource.h>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <string>

namespace hairgen {
namespace {

// A value in kB from a "Key:   123 kB" line of a /proc file, in bytes; 0 when absent.
uint64_t procValue(const char* file, const char* key) {
  std::ifstream in(file);
  std::string line;
  const std::string prefix = std::string(key) + ":";
  while (std::getline(in, line))
    if (line.compare(0, prefix.size(), prefix) == 0) return std::stoull(line.substr(prefix.size())) * 1024;
  return 0;
}

// Libraries, thread stacks and the GL driver's own allocations: never handed to the work.
constexpr uint64_t kReserve = 512ull << 20;

}  // namespace

uint64_t memoryBudget() {
  uint64_t available = procValue("/proc/meminfo", "MemAvailable");
  if (available == 0) available = 1ull << 32;  // no /proc: assume 4 GB rather than nothing
  rlimit limit{};
  if (getrlimit(RLIMIT_AS, &limit) == 0 && limit.rlim_cur != RLIM_INFINITY) {
    const uint64_t used = procValue("/proc/self/status", "VmSize");
    const uint64_t left = limit.rlim_cur > used ? limit.rlim_cur - used : 0;
    available = std::min<uint64_t>(available, left);
  }
  return available > kReserve ? available - kReserve : 0;
}

uint64_t peakResidentBytes() {
  return procValue("/proc/self/status", "VmHWM");
}

std::string formatBytes(uint64_t bytes) {
  char buffer[32];
  const double b = double(bytes);
  if (b >= 1e12)
    std::snprintf(buffer, sizeof buffer, "%.3g TB", b / 1e12);
  else if (b >= 1e9)
    std::snprintf(buffer, sizeof buffer, "%.1f GB", b / 1e9);
  else if (b >= 1e6)
    std::snprintf(buffer, sizeof buffer, "%.0f MB", b / 1e6);
  else
    std::snprintf(buffer, sizeof buffer, "%.0f kB", b / 1e3);
  return buffer;
}

}  // namespace hairgen
