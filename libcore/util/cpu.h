// What the processor offers that hairgen's kernels choose between at run time.
#pragma once

namespace hairgen {

// Whether the kernels built for AVX-512 F and DQ can run (libcore/physics/anjyo_lanes.cpp, 16 floats a
// vector; spring_lanes.cpp, 8 doubles).
inline bool hasAvx512() {
  static const bool has = __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq");
  return has;
}

}  // namespace hairgen
