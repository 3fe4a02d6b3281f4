// What the processor offers that hairgen's kernels choose between at run time.
#pragma once

namespace hairgen {

// Whether the vector kernels of 8 doubles (libcore/physics/anjyo_lanes.cpp, spring_lanes.cpp) can run:
// AVX-512 F and DQ.
inline bool hasAvx512() {
  static const bool has = __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq");
  return has;
}

}  // namespace hairgen
