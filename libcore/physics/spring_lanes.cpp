// Model springs' substep (Petrovic et al. 2006 §5 keyhairs; spring_dynamics.cpp, stepStrand: predict,
// the XPBD stretch solve of Macklin, Müller and Chentanez 2016, the twist springs and collisions, the
// second solve, the velocities) for kLanes strands of the same segment count at once, in AVX-512
// vectors, and the posing of a strand's points eight at a time: the same operations in the same order on
// each lane, so every lane's bits are the strand's own (IEEE arithmetic and square roots are exact per
// lane; this file and spring_dynamics.cpp are built without contraction into fused multiply-adds). The
// solves are chains of divisions down the strand and back, whose latency the strand-by-strand code
// waits on; eight independent strands fill those waits. A point near a collision shape is pushed out by
// the strand's own code, lane by lane.
#include <algorithm>

#include <glm/glm.hpp>

#include "libcore/physics/lanes.h"
#include "libcore/physics/spring_dynamics.h"
#include "libcore/physics/tridiagonal.h"

// Everything below runs on AVX-512 only (the dispatch in spring_dynamics.cpp checks the processor), and is
// built for it whole: GCC 12 fails (an internal compiler error) on this file's vector masks when they are
// first compiled for the default target and then inlined into an AVX-512 function.
#pragma GCC push_options
#pragma GCC target("avx512f,avx512dq")

namespace hairgen {

using namespace lanes;
static_assert(SpringHair::kLanes == kLaneWidth);

struct SpringHair::Lanes {
  // A block's arrays live on the stack, sized for the longest lane strand: about 260 KB for a step
  // (210 KB by -fstack-usage before the BDF2 history's two more arrays in predict), well inside TBB's
  // 4 MB worker stacks; a strand of n segments touches n + 2 of each.
  static constexpr size_t kMost = kMaxLaneSegments + 2;
  static constexpr uint32_t kAhead = 4;  // points
  // A block's lanes: the points and what the stretch solve reads of them.
  struct Block {
    V3 x[kMost];
    V3 lastMove[kMost];  // BDF2's w, read by predict and by the finish that replaces it
    Vd inverseMass[kMost], length[kMost], compliance[kMost];
    uint32_t p0[kLaneWidth];
    // 1 in lanes whose strand is not solved (past `count`, or not taken). (A double: GCC 12 fails on a
    // mask kept in a variable and or-ed with a comparison.)
    Vd done;
  };
  // The block's constants and the points of its lanes that are taken.
  HAIRGEN_LANE static void gather(const SpringHair& hair, size_t block, const size_t* strands, size_t count,
                                  uint32_t n, const bool* take, Block& b) {
    for (size_t l = 0; l < kLaneWidth; ++l) {
      const bool in = l < count && take[l];
      b.p0[l] = hair.rest_.firstPoint[strands[l < count ? l : 0]];
      b.done[l] = in ? 0.0 : 1.0;
    }
    const LanePoint* at = &hair.lanePoints_[hair.laneFirst_[block]];
    for (uint32_t j = 0; j <= n; ++j) {
      // Asked of memory ahead: more streams (eight strands' points and the constants) than the hardware
      // prefetcher follows.
      if (j + kAhead <= n) {
        const char* ahead = reinterpret_cast<const char*>(&at[j + kAhead]);
        for (size_t c = 0; c < sizeof(LanePoint); c += 64) __builtin_prefetch(ahead + c);
        for (size_t l = 0; l < kLaneWidth; ++l) __builtin_prefetch(&hair.x_[b.p0[l] + j + kAhead]);
      }
      for (size_t l = 0; l < kLaneWidth; ++l) setLane(b.x[j], l, hair.x_[b.p0[l] + j]);
      b.inverseMass[j] = load(at[j].inverseMass);
      b.length[j] = load(at[j].length);
      b.compliance[j] = load(at[j].compliance);
    }
  }
  HAIRGEN_LANE static void scatter(SpringHair& hair, size_t count, uint32_t n, const Block& b) {
    for (size_t l = 0; l < count; ++l) {
      if (b.done[l] > 0.0) continue;
      for (uint32_t j = 1; j <= n; ++j) hair.x_[b.p0[l] + j] = lane(b.x[j], l);
    }
  }
  HAIRGEN_LANE static void predict(const SpringHair& hair, size_t block, const size_t* strands, size_t count,
                                   uint32_t n, const AccelerationField& field, double dt, Block& b,
                                   V3* before);
  HAIRGEN_LANE static void projectStretch(uint32_t n, double dt, Block& b);
  // constrain's operations on the block's points, lane by lane (the collisions of the lanes near a shape
  // with the strand's own code); 0 in `done` where a lane's point moved.
  HAIRGEN_LANE static void constrain(const SpringHair& hair, size_t block, size_t count, uint32_t n,
                                     double dt, Block& b);
  [[gnu::target("avx512f,avx512dq")]] static void stepAvx512(SpringHair& hair, size_t block,
                                                             const size_t* strands, size_t count, uint32_t n,
                                                             const AccelerationField& field, double dt) {
    Block b;
    const bool all[kLaneWidth] = {true, true, true, true, true, true, true, true};
    gather(hair, block, strands, count, n, all, b);
    V3 was[kMost];
    predict(hair, block, strands, count, n, field, dt, b, was);
    projectStretch(n, dt, b);
    constrain(hair, block, count, n, dt, b);
    bool again = false;
    for (size_t l = 0; l < count; ++l) again = again || !(b.done[l] > 0.0);
    if (again) projectStretch(n, dt, b);
    b.done = splat(0.0);
    for (size_t l = count; l < kLaneWidth; ++l) b.done[l] = 1.0;
    scatter(hair, count, n, b);
    // finish: v⁺ = 3/2 w⁺ − 1/2 w, the history moved on.
    for (uint32_t j = 1; j <= n; ++j) {
      const V3 move = (b.x[j] - was[j]) / splat(dt);
      const V3 v = splat(kThreeHalves) * move - splat(0.5) * b.lastMove[j];
      for (size_t l = 0; l < count; ++l) {
        const uint32_t p = b.p0[l] + j;
        hair.previousV_[p] = hair.v_[p];
        hair.v_[p] = lane(v, l);
        hair.lastMove_[p] = lane(move, l);
      }
    }
  }
  [[gnu::target("avx512f,avx512dq")]] static void projectStretchAvx512(SpringHair& hair, size_t block,
                                                                       const size_t* strands, size_t count,
                                                                       uint32_t n, double dt,
                                                                       const bool* take) {
    Block b;
    gather(hair, block, strands, count, n, take, b);
    projectStretch(n, dt, b);
    scatter(hair, count, n, b);
  }
};

namespace {

using Vi = long long __attribute__((vector_size(kLaneWidth * sizeof(long long))));

// Eight consecutive points (24 doubles, x y z each) as a V3.
HAIRGEN_LANE V3 loadEight(const glm::dvec3* p) {
  Vd a, b, c;
  __builtin_memcpy(&a, &p[0].x, sizeof(Vd));
  __builtin_memcpy(&b, reinterpret_cast<const double*>(p) + kLaneWidth, sizeof(Vd));
  __builtin_memcpy(&c, reinterpret_cast<const double*>(p) + 2 * kLaneWidth, sizeof(Vd));
  return {__builtin_shuffle(__builtin_shuffle(a, b, Vi{0, 3, 6, 9, 12, 15, 0, 0}), c,
                            Vi{0, 1, 2, 3, 4, 5, 10, 13}),
          __builtin_shuffle(__builtin_shuffle(a, b, Vi{1, 4, 7, 10, 13, 0, 0, 0}), c,
                            Vi{0, 1, 2, 3, 4, 8, 11, 14}),
          __builtin_shuffle(__builtin_shuffle(a, b, Vi{2, 5, 8, 11, 14, 0, 0, 0}), c,
                            Vi{0, 1, 2, 3, 4, 9, 12, 15})};
}
HAIRGEN_LANE V3 loadEight(const glm::vec3* p) {
  V3 r;
  for (size_t l = 0; l < kLaneWidth; ++l) setLane(r, l, glm::dvec3(p[l]));
  return r;
}
// glm's dmat3 × dvec3.
HAIRGEN_LANE V3 rotate(const glm::dmat3& m, const V3& v) {
  const V3 m0 = splat(m[0]), m1 = splat(m[1]), m2 = splat(m[2]);
  return {m0.x * v.x + m1.x * v.y + m2.x * v.z, m0.y * v.x + m1.y * v.y + m2.y * v.z,
          m0.z * v.x + m1.z * v.y + m2.z * v.z};
}

}  // namespace

[[gnu::target("avx512f,avx512dq")]] void SpringHair::poseEightLanes(size_t s, uint32_t j0, const Pose& pose,
                                                                    Strands& out) const {
  // posedInto's operations, a point a lane.
  const uint32_t p = rest_.firstPoint[s] + j0;
  const V3 x = loadEight(&x_[p]), next = loadEight(&x_[p + 1]), rest = loadEight(&xRest_[p]);
  const V3 centre = splat(pose.centre);
  const V3 posed = rotate(pose.rotation, rest + (x - rest) - centre) + centre + splat(pose.translation);
  const V3 e = next - x;
  const V3 dir = (1.0 / sqrt(dot(e, e))) * e;  // glm::normalize
  const V3 restDir = loadEight(&restUnit_[p]), tangent = loadEight(&restTangents_[p]);
  // transportFast(restDir, dir, tangent)
  const V3 w = cross(restDir, dir);
  const Vd c = dot(restDir, dir);
  const V3 turned = c * tangent + cross(w, tangent) + (dot(w, tangent) / (1.0 + c)) * w;
  V3 t = select(c < -1.0 + 1e-12, V3{-tangent.x, -tangent.y, -tangent.z}, turned);
  if (!pose.isIdentity()) t = rotate(pose.rotation, t);
  for (size_t l = 0; l < kLaneWidth; ++l) {
    out.points[p + l] = glm::vec3(lane(posed, l));
    out.tangents[p + l] = glm::vec3(lane(t, l));
  }
}

void SpringHair::stepLanes(size_t block, const size_t* strands, size_t count, uint32_t n,
                           const AccelerationField& field, double dt) {
  Lanes::stepAvx512(*this, block, strands, count, n, field, dt);
}

void SpringHair::projectStretchLanes(size_t block, const size_t* strands, size_t count, uint32_t n, double dt,
                                     const bool* take) {
  Lanes::projectStretchAvx512(*this, block, strands, count, n, dt, take);
}

// SpringHair::predict's operations in its order, lane by lane; the old points into `before`.
[[gnu::target("avx512f,avx512dq")]] void SpringHair::Lanes::predict(const SpringHair& hair, size_t block,
                                                                    const size_t* strands, size_t count,
                                                                    uint32_t n,
                                                                    const AccelerationField& field, double dt,
                                                                    Block& b, V3* before) {
  const LanePoint* at = &hair.lanePoints_[hair.laneFirst_[block]];
  V3 v[kMost], previousV[kMost], unit[kMost], turn[kMost], force[kMost];
  V3* lastMove = b.lastMove;
  Vd inverseLength[kMost];
  for (size_t l = 0; l < kLaneWidth; ++l) {
    setLane(unit[0], l, hair.rootDirection_[strands[l < count ? l : 0]]);
    for (uint32_t j = 1; j <= n; ++j) {
      const uint32_t p = b.p0[l] + j;
      setLane(v[j], l, hair.v_[p]);
      setLane(previousV[j], l, hair.previousV_[p]);
      setLane(lastMove[j], l, hair.lastMove_[p]);
    }
  }
  inverseLength[n + 1] = splat(0.0);
  lastMove[0] = splat(glm::dvec3(0.0));  // the root's
  const double thirdDt = dt / 3.0;
  const Vd third = splat(thirdDt);
  for (uint32_t j = 1; j <= n; ++j) {
    inverseLength[j] = 1.0 / b.length[j];
    unit[j] = inverseLength[j] * ((b.x[j] - b.x[j - 1]) + third * (lastMove[j] - lastMove[j - 1]));
  }
  unit[n + 1] = splat(glm::dvec3(0.0));
  for (uint32_t j = 0; j < n; ++j)
    turn[j] = load(at[j].bend) * (load(at[j].target) - (unit[j + 1] - unit[j]));
  turn[n] = turn[n + 1] = splat(glm::dvec3(0.0));
  const V3 base = splat(field.base), centre = splat(field.centre), alpha = splat(field.alpha),
           omega = splat(field.omega);
  const Vd twoThirdsDt = splat(kTwoThirds * dt);
  for (uint32_t i = 1; i <= n; ++i) {
    V3 f = inverseLength[i] * turn[i - 1] + inverseLength[i + 1] * turn[i + 1] -
           (inverseLength[i] + inverseLength[i + 1]) * turn[i];
    f = f - load(at[i].restTension) * unit[i];
    if (i < n) f = f + load(at[i + 1].restTension) * unit[i + 1];
    V3 a = base;  // AccelerationField::at
    if (field.rotating) {
      const V3 r = b.x[i] - centre;
      a = base - cross(alpha, r) - cross(omega, cross(omega, r)) - splat(2.0) * cross(omega, v[i]);
    }
    const Vd mass = load(at[i].mass);
    f = f + mass * a;
    force[i] = mass * (splat(kFourThirds) * v[i] - splat(kOneThird) * previousV[i]) + twoThirdsDt * f;
  }
  for (uint32_t i = 1; i <= n; ++i) {
    if (i >= 2) force[i] = force[i] - load(at[i].lower1) * force[i - 1];
    if (i >= 3) force[i] = force[i] - load(at[i].lower2) * force[i - 2];
  }
  for (uint32_t i = 1; i <= n; ++i) force[i] = load(at[i].inverseD) * force[i];
  for (uint32_t i = n; i >= 1; --i) {
    if (i + 1 <= n) force[i] = force[i] - load(at[i + 1].lower1) * force[i + 1];
    if (i + 2 <= n) force[i] = force[i] - load(at[i + 2].lower2) * force[i + 2];
  }
  for (uint32_t i = 1; i <= n; ++i) {
    before[i] = b.x[i];
    b.x[i] = b.x[i] + (third * lastMove[i] + twoThirdsDt * force[i]);
  }
}

[[gnu::target("avx512f,avx512dq")]] void SpringHair::Lanes::constrain(const SpringHair& hair, size_t block,
                                                                      size_t count, uint32_t n, double dt,
                                                                      Block& b) {
  const LanePoint* at = &hair.lanePoints_[hair.laneFirst_[block]];
  V3* x = b.x;
  Vd moved = splat(0.0);  // 1 where a lane's point moved (a double, as Block::done)
  const double dt2 = dt * dt;
  for (uint32_t i = 0; i + 3 <= n; ++i) {
    const Vd compliance = load(at[i].twistCompliance);
    const Vm spring = compliance >= 0.0;  // (scalar: skipped where < 0)
    moved = select(spring, splat(1.0), moved);
    const Vd ia = b.inverseMass[i], ib = b.inverseMass[i + 3];
    const V3 e = x[i + 3] - x[i];
    const Vd len = sqrt(dot(e, e));
    const Vd wsum = ia + ib + compliance / dt2;
    const Vd dl = -(len - load(at[i].twistLength)) / wsum;
    x[i] = select(spring & (ia > 0.0), x[i] - ((ia * dl) * e) / len, x[i]);  // a root stays
    x[i + 3] = select(spring, x[i + 3] + ((ib * dl) * e) / len, x[i + 3]);
  }
  for (size_t c = 0; c < hair.shapes_.size(); ++c) {
    const V3 centre = splat(hair.shapes_[c].centre);
    for (uint32_t i = 1; i <= n; ++i) {
      const V3 v = x[i] - centre;
      const Vm near = dot(v, v) < hair.shapeReach2_[c];
      for (size_t l = 0; l < count; ++l) {
        if (!near[l]) continue;
        glm::dvec3 point = lane(x[i], l);
        if (!hair.collide(c, b.p0[l] + i, point)) continue;
        setLane(x[i], l, point);
        moved[l] = 1.0;
      }
    }
  }
  for (size_t l = 0; l < kLaneWidth; ++l) b.done[l] = l < count && moved[l] > 0.0 ? 0.0 : 1.0;
}

[[gnu::target("avx512f,avx512dq")]] void SpringHair::Lanes::projectStretch(uint32_t n, double dt, Block& b) {
  constexpr size_t w = kLaneWidth;
  V3* x = b.x;
  V3 u[kMost];
  Vd alpha[kMost], base[kMost], inverseLength[kMost], lambda[kMost], diag[kMost], upper[kMost], rhs[kMost],
      inverseDiag[kMost];
  const Vd* inverseMass = b.inverseMass;
  const Vd* length = b.length;
  Vd done = b.done;
  if (n == 0) return;  // (never: a lane strand has a segment)
  const double dt2 = dt * dt;
  for (uint32_t j = 1; j <= n; ++j) {
    alpha[j] = b.compliance[j] / dt2;
    base[j] = inverseMass[j - 1] + inverseMass[j] + alpha[j];
    inverseLength[j] = 1.0 / length[j];
    lambda[j] = splat(0.0);
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
    solveTridiagonal(upper, diag, rhs, inverseDiag, n);
    const Vm keep = done > 0.0;
    for (uint32_t j = 1; j <= n; ++j) {
      lambda[j] = select(keep, lambda[j], lambda[j] + rhs[j]);
      const V3 along = j < n ? rhs[j] * u[j] - rhs[j + 1] * u[j + 1] : rhs[j] * u[j] - splat(glm::dvec3(0.0));
      x[j] = select(keep, x[j], x[j] + inverseMass[j] * along);
    }
  }
}

}  // namespace hairgen

#pragma GCC pop_options
