// Model springs' stretch solve (Petrovic et al. 2006 §5 keyhairs kept inextensible by XPBD, Macklin,
// Müller and Chentanez 2016; spring_dynamics.cpp, projectStretch) for kLanes strands of the same
// segment count at once, in AVX-512 vectors: the same operations in the same order on each lane, so
// every lane's bits are the strand's own (IEEE arithmetic and square roots are exact per lane; this file
// and spring_dynamics.cpp are built without contraction into fused multiply-adds). The solve is a chain
// of divisions down the strand and back, whose latency the strand-by-strand code waits on; eight
// independent strands fill those waits.
#include <algorithm>

#include "libcore/physics/lanes.h"
#include "libcore/physics/spring_dynamics.h"

// Everything below runs on AVX-512 only (the dispatch in spring_dynamics.cpp checks the processor), and is
// built for it whole: GCC 12 fails (an internal compiler error) on this file's vector masks when they are
// first compiled for the default target and then inlined into an AVX-512 function.
#pragma GCC push_options
#pragma GCC target("avx512f,avx512dq")

namespace hairgen {

using namespace lanes;
static_assert(SpringHair::kLanes == kLaneWidth);

struct SpringHair::Lanes {
  HAIRGEN_LANE static void projectStretch(SpringHair& hair, const size_t* strands, size_t count, uint32_t n,
                                          double dt, const bool* take);
  [[gnu::target("avx512f,avx512dq")]] static void projectStretchAvx512(SpringHair& hair,
                                                                       const size_t* strands, size_t count,
                                                                       uint32_t n, double dt,
                                                                       const bool* take) {
    projectStretch(hair, strands, count, n, dt, take);
  }
};

void SpringHair::projectStretchLanes(const size_t* strands, size_t count, uint32_t n, double dt,
                                     const bool* take) {
  Lanes::projectStretchAvx512(*this, strands, count, n, dt, take);
}

void SpringHair::Lanes::projectStretch(SpringHair& hair, const size_t* strands, size_t count, uint32_t n,
                                       double dt, const bool* take) {
  constexpr size_t w = kLaneWidth;
  // The strands' points, masses, lengths and compliances, lane by lane; a lane without a strand (or not
  // taking part) repeats the first strand's and is never written back.
  V3 x[kMaxLaneSegments + 1], u[kMaxLaneSegments + 2];
  Vd inverseMass[kMaxLaneSegments + 1], length[kMaxLaneSegments + 1], alpha[kMaxLaneSegments + 1],
      base[kMaxLaneSegments + 1], inverseLength[kMaxLaneSegments + 1], lambda[kMaxLaneSegments + 1],
      diag[kMaxLaneSegments + 1], upper[kMaxLaneSegments + 1], rhs[kMaxLaneSegments + 1],
      inverseDiag[kMaxLaneSegments + 1];
  uint32_t p0[w];
  // 1 in lanes whose strand has finished (or never started): the strand's loop has left them. (A double:
  // GCC 12 fails on a mask kept in a variable and or-ed with a comparison.)
  Vd done;
  for (size_t l = 0; l < w; ++l) {
    const bool in = l < count && take[l];
    p0[l] = hair.rest_.firstPoint[strands[in ? l : 0]];
    done[l] = in ? 0.0 : 1.0;
  }
  for (uint32_t j = 0; j <= n; ++j)
    for (size_t l = 0; l < w; ++l) {
      const uint32_t p = p0[l] + j;
      setLane(x[j], l, hair.x_[p]);
      inverseMass[j][l] = hair.inverseMass_[p];
      length[j][l] = hair.length_[p];
      alpha[j][l] = hair.compliance_[p];
      lambda[j][l] = 0.0;
    }
  const double dt2 = dt * dt;
  for (uint32_t j = 1; j <= n; ++j) {
    alpha[j] = alpha[j] / dt2;
    base[j] = inverseMass[j - 1] + inverseMass[j] + alpha[j];
    inverseLength[j] = 1.0 / length[j];
  }
  constexpr int kMaxPasses = 32, kIterations = 1;
  constexpr double kStretchTolerance = 1e-3;
  for (int it = 0; it < kMaxPasses; ++it) {
    Vd worst = splat(0.0);
    for (uint32_t j = 1; j <= n; ++j) {
      const V3 e = x[j] - x[j - 1];
      const Vd len = sqrt(dot(e, e));
      const Vd off = abs(len - length[j]) * inverseLength[j];
      worst = select(worst < off, off, worst);  // std::max(worst, off)
      u[j] = (1.0 / len) * e;
      diag[j] = base[j];
      rhs[j] = -(len - length[j]) - alpha[j] * lambda[j];
    }
    if (it >= kIterations) done = select(worst <= kStretchTolerance, splat(1.0), done);
    bool all = true;
    for (size_t l = 0; l < w; ++l) all = all && done[l] > 0.0;
    if (all) break;
    for (uint32_t j = 1; j < n; ++j) upper[j] = -inverseMass[j] * dot(u[j], u[j + 1]);
    inverseDiag[1] = 1.0 / diag[1];
    for (uint32_t j = 2; j <= n; ++j) {
      const Vd m = upper[j - 1] * inverseDiag[j - 1];
      diag[j] -= m * upper[j - 1];
      rhs[j] -= m * rhs[j - 1];
      inverseDiag[j] = 1.0 / diag[j];
    }
    rhs[n] *= inverseDiag[n];
    for (uint32_t j = n - 1; j >= 1; --j) rhs[j] = (rhs[j] - upper[j] * rhs[j + 1]) * inverseDiag[j];
    const Vm keep = done > 0.0;
    for (uint32_t j = 1; j <= n; ++j) {
      lambda[j] = select(keep, lambda[j], lambda[j] + rhs[j]);
      const V3 along = j < n ? rhs[j] * u[j] - rhs[j + 1] * u[j + 1] : rhs[j] * u[j] - splat(glm::dvec3(0.0));
      x[j] = select(keep, x[j], x[j] + inverseMass[j] * along);
    }
  }
  for (size_t l = 0; l < count; ++l) {
    if (!take[l]) continue;
    for (uint32_t j = 1; j <= n; ++j) hair.x_[p0[l] + j] = lane(x[j], l);
  }
}

}  // namespace hairgen

#pragma GCC pop_options
