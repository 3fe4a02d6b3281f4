// What this machine and process allow: memory for the work, and what the process has used. Every
// stage estimates its work against memoryBudget() before it allocates, so a config that cannot fit is
// refused with exit 2 instead of ending in "out of memory".
#pragma once

#include <cstdint>
#include <string>

namespace hairgen {

// Bytes the process may still allocate: the smaller of the memory the kernel reports available
// (MemAvailable) and what the address-space limit (ulimit -v, prlimit --as) leaves beyond the
// process's current size, less a reserve for libraries, stacks and the GL driver.
uint64_t memoryBudget();

// The process's peak resident set so far (VmHWM), bytes; 0 where /proc does not say.
uint64_t peakResidentBytes();

// "1.5 GB", "230 MB", "12 kB": for messages.
std::string formatBytes(uint64_t bytes);

}  // namespace hairgen
