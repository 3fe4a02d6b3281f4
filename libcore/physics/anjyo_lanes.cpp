// Anjyo et al. 1992 §3, the substep of anjyo_dynamics.cpp for kLanes strands at once in AVX-512 vectors:
// the same operations in the same order on each lane, so every lane's bits are stepStrand's (IEEE
// arithmetic and square roots are exact per lane; this file is built without contraction into fused
// multiply-adds). What branches per segment (a segment that meets a collision shape or its joint limit)
// is done lane by lane with the strand's own code.
#include <algorithm>
#include <cmath>
#include <optional>

#include "libcore/physics/anjyo_dynamics.h"
#include "libcore/physics/anjyo_sincos.h"
#include "libcore/physics/lanes.h"

namespace hairgen {

namespace {

using namespace lanes;
static_assert(AnjyoHair::kLanes == kLaneWidth);

// Where penetration() of an ellipsoid (strand_energy.cpp) at the centre's offset v exceeds the depth
// its node sat at, as settle() tests it: the same operations, lane by lane. `depth` per point, the node
// of lane l being point p0[l] + node (none past its strand's count[l] segments).
HAIRGEN_LANE Vm deeperThanAtRest(const CollisionShape& shape, const V3& v, const double* depth,
                                 const uint32_t (&p0)[AnjyoHair::kLanes],
                                 const uint32_t (&count)[AnjyoHair::kLanes], uint32_t node) {
  const V3 local{dot(v, splat(shape.axes[0])), dot(v, splat(shape.axes[1])), dot(v, splat(shape.axes[2]))};
  const Vd dist = sqrt(dot(local, local));
  const V3 scaled{local.x / shape.halfExtents.x, local.y / shape.halfExtents.y,
                  local.z / shape.halfExtents.z};
  const Vd ratio = sqrt(dot(scaled, scaled));
  const double smallest = std::min(shape.halfExtents.x, std::min(shape.halfExtents.y, shape.halfExtents.z));
  const Vd inside = select(greater(ratio, Vd{}), dist / ratio - dist, splat(smallest));
  Vd allowed;
  for (size_t l = 0; l < AnjyoHair::kLanes; ++l)
    allowed[l] = node <= count[l] ? std::max(depth[p0[l] + node], 0.0) : 0.0;
  return !lessEqual(inside, allowed + 1e-9);
}

}  // namespace

struct AnjyoHair::Lanes {
  // What segment j of a block reads (its constants, state and rest point), asked of memory ahead of its
  // turn: the step reads five streams at once, more than the hardware prefetcher keeps ahead of.
  HAIRGEN_LANE static void prefetchAhead(const AnjyoHair& hair, size_t block, size_t j) {
    const size_t at = hair.blockFirst_[block] + j;
    if (at >= hair.lanes_.size()) return;
    const char* segment = reinterpret_cast<const char*>(&hair.lanes_[at]);
    for (size_t b = 0; b < sizeof(LaneSegment); b += 64) __builtin_prefetch(segment + b);
    const char* point = reinterpret_cast<const char*>(&hair.lanePoints_[at + block]);
    for (size_t b = 0; b < sizeof(LanePoint); b += 64) __builtin_prefetch(point + b);
    const char* state =
        reinterpret_cast<const char*>(&hair.state_[kStateHeader + at * kStateValues * kLanes]);
    for (size_t b = 0; b < kStateValues * kLanes * sizeof(double); b += 64) __builtin_prefetch(state + b, 1);
  }
  struct PoseOut;
  HAIRGEN_LANE static void step(AnjyoHair& hair, size_t s0, const AccelerationField& field, double dt,
                                const Pose* pose, Strands* out);
  HAIRGEN_LANE static void pose(const AnjyoHair& hair, size_t s0, const Pose& pose, Strands& out);
  // The code built for AVX-512, the instruction set the lanes run on. (Built for AVX2, 8 lanes in pairs
  // of 4, or for SSE2, it was measured slower than the strand-by-strand step: 82 and 87 ms of CPU a frame
  // in SimulateAnjyo against 61.)
  [[gnu::target("avx512f,avx512dq")]] static void stepAvx512(AnjyoHair& hair, size_t s0,
                                                             const AccelerationField& field, double dt,
                                                             const Pose* p, Strands* out) {
    step(hair, s0, field, dt, p, out);
  }
  [[gnu::target("avx512f,avx512dq")]] static void poseAvx512(const AnjyoHair& hair, size_t s0, const Pose& p,
                                                             Strands& out) {
    pose(hair, s0, p, out);
  }
};

void AnjyoHair::stepLanes(size_t s0, const AccelerationField& field, double dt, const Pose* pose,
                          Strands* out) {
  Lanes::stepAvx512(*this, s0, field, dt, pose, out);
}

void AnjyoHair::poseLanes(size_t s0, const Pose& pose, Strands& out) const {
  Lanes::poseAvx512(*this, s0, pose, out);
}

// posedInto's arithmetic, lane by lane: each point is the input point plus its node's motion, posed;
// each tangent the input's turned with its segment by transportFast, then posed. `point` writes point j
// of every lane from its node and the segment it starts (for the last point, the last segment).
struct AnjyoHair::Lanes::PoseOut {
  const AnjyoHair& hair;
  const Pose& pose;
  Strands& out;
  size_t s0, strands;
  const uint32_t (&p0)[kLanes];
  const uint32_t (&count)[kLanes];
  bool still = pose.isIdentity();
  V3 m0 = splat(pose.rotation[0]), m1 = splat(pose.rotation[1]), m2 = splat(pose.rotation[2]);
  V3 dir{}, restDir{};  // per lane, of the segment point j starts (or the last one)
  Vm moved{};           // whether that segment has left its rest direction

  HAIRGEN_LANE V3 rotate(const V3& v) const {  // glm's dmat3 × dvec3
    return {m0.x * v.x + m1.x * v.y + m2.x * v.z, m0.y * v.x + m1.y * v.y + m2.y * v.z,
            m0.z * v.x + m1.z * v.y + m2.z * v.z};
  }
  // Segment j's direction now, its rest direction and angles, for the lanes in `here`.
  HAIRGEN_LANE void segment(Vm here, const V3& now, const V3& rest, Vd theta, Vd phi) {
    dir = select(here, now, dir);
    restDir = select(here, rest, restDir);
    moved = select(here, nonZero(theta) | nonZero(phi), moved);
  }
  HAIRGEN_LANE void point(size_t j, const V3& node) {
    const LanePoint& at = hair.lanePoints_[hair.blockFirst_[s0 / kLanes] + s0 / kLanes + j];
    const V3 restPoint = load(at.point), forward = load(at.forward), tangent = load(at.tangent);
    const V3 posed = rotate(restPoint + (node - forward) - splat(pose.centre)) + splat(pose.centre) +
                     splat(pose.translation);
    // transportFast(restDir, dir, tangent)
    const V3 w = cross(restDir, dir);
    const Vd c = dot(restDir, dir);
    const V3 turned = c * tangent + cross(w, tangent) + (dot(w, tangent) / (1.0 + c)) * w;
    const V3 flipped{-tangent.x, -tangent.y, -tangent.z};
    V3 t = select(moved, select(less(c, splat(-1.0 + 1e-12)), flipped, turned), tangent);
    if (!still) t = rotate(t);
    // Rounded to floats in vectors (as glm::vec3's cast rounds each), then stored lane by lane.
    const Vf px = toFloats(posed.x), py = toFloats(posed.y), pz = toFloats(posed.z);
    const Vf tx = toFloats(t.x), ty = toFloats(t.y), tz = toFloats(t.z);
    for (size_t l = 0; l < kLanes; ++l) {
      if (s0 + l >= strands || j > count[l]) continue;
      out.points[p0[l] + j] = glm::vec3(px[l], py[l], pz[l]);
      out.tangents[p0[l] + j] = glm::vec3(tx[l], ty[l], tz[l]);
    }
  }
};

void AnjyoHair::Lanes::pose(const AnjyoHair& hair, size_t s0, const Pose& pose, Strands& out) {
  constexpr size_t n = kLanes;
  const size_t strands = hair.rest_.strandCount(), block = s0 / n;
  const LaneSegment* segments = &hair.lanes_[hair.blockFirst_[block]];
  const size_t most = hair.blockFirst_[block + 1] - hair.blockFirst_[block];
  uint32_t count[n], p0[n];
  V3 node{};
  for (size_t l = 0; l < n; ++l) {
    const size_t s = s0 + l;
    count[l] = s < strands ? hair.firstSegment_[s + 1] - hair.firstSegment_[s] : 0;
    p0[l] = s < strands ? hair.rest_.firstPoint[s] : 0;
    if (s < strands) setLane(node, l, hair.restForward_[p0[l]]);
  }
  Vm counts;
  for (size_t l = 0; l < n; ++l) counts[l] = count[l];
  PoseOut writer{hair, pose, out, s0, strands, p0, count};
  for (size_t j = 0; j <= most; ++j) {
    if (j > 0) node = node + load(segments[j - 1].length) * writer.dir;
    if (j < most) {
      const double* state = &hair.state_[kStateHeader + (hair.blockFirst_[block] + j) * kStateValues * n];
      auto value = [&](StateValue v) HAIRGEN_LANE_LAMBDA { return loadLanes(state + v * n); };
      const LaneSegment& segment = segments[j];
      const Vm here =
          Vm{} + int64_t(j) < counts;  // a lane past its strand's last segment keeps the last one's
      const V3 rest = load(segment.rest);
      Vd st, ct, sp, cp;
      sinCos(value(kTheta), st, ct);
      sinCos(value(kPhi), sp, cp);
      const V3 now = ct * (cp * rest + sp * load(segment.side)) + st * load(segment.pole);
      writer.segment(here, now, rest, value(kTheta), value(kPhi));
    }
    writer.point(j, node);
  }
}

void AnjyoHair::Lanes::step(AnjyoHair& hair, size_t s0, const AccelerationField& field, double dt,
                            const Pose* pose, Strands* out) {
  constexpr size_t n = kLanes;
  const size_t strands = hair.rest_.strandCount(), block = s0 / n;
  const LaneSegment* segments = &hair.lanes_[hair.blockFirst_[block]];
  const size_t most = hair.blockFirst_[block + 1] - hair.blockFirst_[block];
  const double keep = std::max(0.0, 1.0 - hair.damping_ * dt), dt2 = dt * dt;
  const CollisionShape* head = hair.head_ >= 0 ? &hair.shapes_[size_t(hair.head_)] : nullptr;
  const bool pseudo = head && hair.pseudoEpsilon_ < 1.0;
  uint32_t count[n], p0[n];
  V3 node{};
  for (size_t l = 0; l < n; ++l) {
    const size_t s = s0 + l;
    count[l] = s < strands ? hair.firstSegment_[s + 1] - hair.firstSegment_[s] : 0;
    p0[l] = s < strands ? hair.rest_.firstPoint[s] : 0;
    if (s < strands) setLane(node, l, hair.restForward_[p0[l]]);
  }
  Vm counts;
  for (size_t l = 0; l < n; ++l) counts[l] = count[l];
  V3 nodeVelocity{}, newBefore{};
  // The new state posed, point by point as its nodes are placed, where asked for (stepAndPose).
  std::optional<PoseOut> writer;
  if (out) writer.emplace(PoseOut{hair, *pose, *out, s0, strands, p0, count});
  const V3 base = splat(field.base - hair.restAcceleration_);
  const V3 restAcceleration = splat(hair.restAcceleration_);
  for (size_t j = 0; j < most; ++j) {
    const LaneSegment& segment = segments[j];
    prefetchAhead(hair, block, j + 2);
    // The block's state for segment j: each value a vector of the lanes (anjyo_dynamics.h, state()).
    double* state = &hair.state_[kStateHeader + (hair.blockFirst_[block] + j) * kStateValues * n];
    auto value = [&](StateValue v) HAIRGEN_LANE_LAMBDA { return loadLanes(state + v * n); };
    const Vd theta0 = value(kTheta), phi0 = value(kPhi), thetaPrev = value(kThetaPrev),
             phiPrev = value(kPhiPrev);
    Vd st, ct, sp, cp;
    sinCos(theta0, st, ct);
    sinCos(phi0, sp, cp);
    const Vm active =
        Vm{} + int64_t(j) < counts;  // lanes whose strand has segment j; the others keep their rest state
    const V3 rest = load(segment.rest), pole = load(segment.pole), side = load(segment.side);
    const V3 across = cp * rest + sp * side;
    const V3 dir = ct * across + st * pole;
    const V3 thetaDir = -st * across + ct * pole, phiDir = -sp * rest + cp * side;
    const Vd d = load(segment.length);
    V3 departure = base;
    if (field.rotating) {
      const V3 turnRate = ((theta0 - thetaPrev) * thetaDir + (phi0 - phiPrev) * ct * phiDir) / splat(dt);
      const V3 mid = node + 0.5 * d * dir;
      // AccelerationField::at, at the midpoint moving at the node's velocity and half the turn's.
      const V3 omega = splat(field.omega), x = mid - splat(field.centre);
      const V3 v = nodeVelocity + 0.5 * d * turnRate;
      departure = splat(field.base) - cross(splat(field.alpha), x) - cross(omega, cross(omega, x)) -
                  splat(2.0) * cross(omega, v);
      departure = departure - restAcceleration;
      nodeVelocity = nodeVelocity + d * turnRate;
    }
    if (pseudo) {
      const ShapeTest& test = hair.shapeTests_[size_t(hair.head_)];
      const V3 v = node - splat(head->centre);
      const V3 s0v = splat(test.scaled[0]), s1v = splat(test.scaled[1]), s2v = splat(test.scaled[2]);
      const V3 r{dot(v, s0v), dot(v, s1v), dot(v, s2v)};
      const Vm nonzero = nonZero(departure.x) | nonZero(departure.y) | nonZero(departure.z);
      const Vm near = less(dot(r, r), splat(test.near2));
      const V3 grad = r.x * s0v + r.y * s1v + r.z * s2v;
      const Vm into = less(dot(grad, departure),
                           hair.pseudoAlpha_ * sqrt(dot(grad, grad)) * sqrt(dot(departure, departure)));
      departure = select(nonzero & near & into, splat(hair.pseudoEpsilon_) * departure, departure);
    }
    const Vd c = load(segment.coefficient);
    const V3 push = departure + load(segment.springOverC) * (rest - dir);
    const Vd thetaAcc = c * dot(push, thetaDir);
    const Vd phiAcc = c * ct * dot(push, phiDir);
    Vd theta = theta0 + keep * (theta0 - thetaPrev) + dt2 * thetaAcc;
    Vd phi = phi0 + keep * (phi0 - phiPrev) + dt2 * phiAcc;
    Vd nst, nct, nsp, ncp;
    sinCos(theta, nst, nct);
    sinCos(phi, nsp, ncp);
    V3 placed = nct * (ncp * rest + nsp * side) + nst * pole;
    // Which lanes may meet a shape or their joint limit: those go through the strand's own code (which
    // finds, as here, that nothing moves where nothing reaches).
    Vm check = less(dot(newBefore, placed), load(segment.cosAllowed) - 1e-12);
    const V3 next = node + d * placed;
    for (size_t c2 = 0; c2 < hair.shapes_.size(); ++c2) {
      if (!(hair.shapes_[c2].penalty > 0.0)) continue;
      const ShapeTest& test = hair.shapeTests_[c2];
      const V3 v = next - splat(hair.shapes_[c2].centre);
      Vm maybe = less(dot(v, v), splat(hair.shapeReach2_[c2]));
      if (test.ellipsoid) {
        const V3 r{dot(v, splat(test.scaled[0])), dot(v, splat(test.scaled[1])),
                   dot(v, splat(test.scaled[2]))};
        maybe = maybe & less(dot(r, r), splat(1.0));
        bool any = false;
        for (size_t l = 0; l < n; ++l) any = any || (maybe[l] && j < count[l]);
        if (any)
          maybe = maybe & deeperThanAtRest(hair.shapes_[c2], v, hair.restDepth_[c2].data(), p0, count,
                                           uint32_t(j + 1));
      }
      check = check | maybe;
    }
    bool settled = false;
    for (size_t l = 0; l < n; ++l) {
      if (!check[l] || j >= count[l]) continue;
      glm::dvec3 placedLane = lane(placed, l);
      if (hair.settle(segment.at(l), p0[l] + j + 1, lane(node, l), lane(newBefore, l), placedLane, theta[l],
                      phi[l])) {
        setLane(placed, l, placedLane);
        settled = true;
      }
    }
    if (settled) {  // the moved lanes' new angles (the others' give the same values again)
      sinCos(theta, nst, nct);
      sinCos(phi, nsp, ncp);
    }
    auto store = [&](StateValue v, Vd to)
                     HAIRGEN_LANE_LAMBDA { storeLanes(state + v * n, select(active, to, value(v))); };
    store(kThetaPrev, theta0);
    store(kPhiPrev, phi0);
    store(kTheta, theta);
    store(kPhi, phi);
    const V3 now = nct * (ncp * rest + nsp * side) + nst * pole;
    if (writer) {
      writer->segment(active, now, rest, theta, phi);
      writer->point(j, node);
    }
    node = node + d * now;
    newBefore = placed;
  }
  if (writer) writer->point(most, node);
}

}  // namespace hairgen
