// The kernel of Anjyo's step (anjyo_kernel.inc), built for any x86-64 and for AVX-512: the same source,
// the same bits (this file is built without contraction into fused multiply-adds).
#include <algorithm>
#include <atomic>
#include <cmath>

#include "libcore/physics/anjyo_dynamics.h"
#include "libcore/physics/float_lanes.h"
#include "libcore/util/atomic_min.h"
#include "libcore/util/random.h"

namespace hairgen {

#define HAIRGEN_ANJYO_KERNEL Portable
#define HAIRGEN_ANJYO_ISA lanes16::PortableIsa
#define HAIRGEN_ANJYO_FN [[gnu::always_inline]] inline
#define HAIRGEN_ANJYO_COLD [[gnu::noinline, gnu::cold]]
#define HAIRGEN_ANJYO_ENTRY
#include "libcore/physics/anjyo_kernel.inc"
#undef HAIRGEN_ANJYO_KERNEL
#undef HAIRGEN_ANJYO_ISA
#undef HAIRGEN_ANJYO_FN
#undef HAIRGEN_ANJYO_COLD
#undef HAIRGEN_ANJYO_ENTRY

#define HAIRGEN_ANJYO_KERNEL Avx512
#define HAIRGEN_ANJYO_ISA lanes16::Avx512Isa
#define HAIRGEN_ANJYO_FN [[gnu::always_inline, gnu::target("avx512f,avx512dq")]] inline
#define HAIRGEN_ANJYO_COLD [[gnu::noinline, gnu::cold, gnu::target("avx512f,avx512dq")]]
#define HAIRGEN_ANJYO_ENTRY [[gnu::target("avx512f,avx512dq")]]
#include "libcore/physics/anjyo_kernel.inc"
#undef HAIRGEN_ANJYO_KERNEL
#undef HAIRGEN_ANJYO_ISA
#undef HAIRGEN_ANJYO_FN
#undef HAIRGEN_ANJYO_COLD
#undef HAIRGEN_ANJYO_ENTRY

void AnjyoHair::Kernels::measure(AnjyoHair& hair, size_t b, float* totals, std::atomic<size_t>& firstBad,
                                 Kernel kernel) {
  if (kernel == Kernel::kAvx512)
    Avx512::runMeasure(hair, b, totals, firstBad);
  else
    Portable::runMeasure(hair, b, totals, firstBad);
}

void AnjyoHair::Kernels::setup(AnjyoHair& hair, size_t b, const SetupParams& params, Kernel kernel) {
  if (kernel == Kernel::kAvx512)
    Avx512::runSetup(hair, b, params);
  else
    Portable::runSetup(hair, b, params);
}

void AnjyoHair::Kernels::angleTrig(AnjyoHair& hair, size_t b, Kernel kernel) {
  if (kernel == Kernel::kAvx512)
    Avx512::runAngleTrig(hair, b);
  else
    Portable::runAngleTrig(hair, b);
}

void AnjyoHair::Kernels::step(AnjyoHair& hair, size_t b, const StepParams& params, const Pose* pose,
                              Strands* out, Kernel kernel) {
  if (kernel == Kernel::kAvx512)
    Avx512::runStep(hair, b, params, pose, out);
  else
    Portable::runStep(hair, b, params, pose, out);
}

void AnjyoHair::Kernels::pose(const AnjyoHair& hair, size_t b, const Pose& pose, Strands& out,
                              Kernel kernel) {
  if (kernel == Kernel::kAvx512)
    Avx512::runPose(hair, b, pose, out);
  else
    Portable::runPose(hair, b, pose, out);
}

void AnjyoHair::Kernels::nodes(const AnjyoHair& hair, size_t b, std::vector<glm::dvec3>& out, Kernel kernel) {
  if (kernel == Kernel::kAvx512)
    Avx512::runNodes(hair, b, out);
  else
    Portable::runNodes(hair, b, out);
}

void AnjyoHair::Kernels::atan2(const float* y, const float* x, float* out, Kernel kernel) {
  if (kernel == Kernel::kAvx512)
    Avx512::runAtan2(y, x, out);
  else
    Portable::runAtan2(y, x, out);
}

}  // namespace hairgen
