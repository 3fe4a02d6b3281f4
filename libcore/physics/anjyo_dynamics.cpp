// Anjyo et al. 1992 §3, as anjyo_dynamics.h describes it.
#include "libcore/physics/anjyo_dynamics.h"
#include "libcore/model/strand_frames.h"
#include "libcore/util/cpu.h"

#include <algorithm>
#include <atomic>
#include <cmath>

#include <tbb/parallel_for.h>

#include "libcore/physics/anjyo_sincos.h"
#include "libcore/physics/strand_energy.h"
#include "libcore/util/error.h"
#include "libcore/util/huge_pages.h"
#include "libcore/util/random.h"

namespace hairgen {
namespace {

constexpr uint64_t kFluctuationKey = 0x666c756374ull;  // "fluct": apart from every other stream

// The kernel asked for, or the strands where this processor has no AVX-512 for the lanes.
AnjyoHair::Kernel available(AnjyoHair::Kernel asked) {
  return asked != AnjyoHair::Kernel::kStrands && hasAvx512() ? AnjyoHair::Kernel::kLanes
                                                             : AnjyoHair::Kernel::kStrands;
}

SegmentFrame frameFor(const glm::dvec3& rest) {
  // A pole across the segment: horizontal where it can be, so that for hanging hair θ swings it in
  // its vertical plane and φ about the vertical.
  glm::dvec3 pole = glm::cross(rest, glm::dvec3(0.0, 1.0, 0.0));
  if (glm::length(pole) < 0.1) pole = glm::cross(rest, glm::dvec3(1.0, 0.0, 0.0));
  pole = glm::normalize(pole);
  return {rest, pole, glm::cross(pole, rest)};
}

// The direction at angles (θ, φ) in frame b.
glm::dvec3 directionAt(const SegmentFrame& b, double theta, double phi) {
  double st, ct, sp, cp;
  sinCos(theta, st, ct);
  sinCos(phi, sp, cp);
  return ct * (cp * b.rest + sp * b.side) + st * b.pole;
}

// The (θ, φ) of unit `dir` nearest to a segment's previous angles: past the pole the same direction is
// (±π − θ, φ + π), and φ is unwrapped, so the recurrences see no jump.
void anglesNear(const SegmentFrame& b, const glm::dvec3& dir, double& theta, double& phi) {
  const double sinLat = std::clamp(glm::dot(dir, b.pole), -1.0, 1.0);
  const double x = glm::dot(dir, b.rest), y = glm::dot(dir, b.side), h = std::hypot(x, y);
  const double lat = std::asin(sinLat), lon = h > 1e-12 ? std::atan2(y, x) : phi;
  auto unwrap = [&](double p) { return p + 2.0 * M_PI * std::round((phi - p) / (2.0 * M_PI)); };
  const double t1 = lat, p1 = unwrap(lon);
  const double t2 = (lat >= 0.0 ? M_PI : -M_PI) - lat, p2 = unwrap(lon + M_PI);
  const bool first = std::abs(t1 - theta) + std::abs(p1 - phi) <= std::abs(t2 - theta) + std::abs(p2 - phi);
  theta = first ? t1 : t2;
  phi = first ? p1 : p2;
}

// The gradient of a shape's inside-outside function at p: the ellipsoid's (the paper's D_i), the
// sphere's radial direction, the box's nearest face normal.
glm::dvec3 outward(const CollisionShape& s, const glm::dvec3& p) {
  const glm::dvec3 v = p - s.centre;
  glm::dvec3 local(glm::dot(v, s.axes[0]), glm::dot(v, s.axes[1]), glm::dot(v, s.axes[2]));
  glm::dvec3 g(0.0);
  switch (s.kind) {
    case ShapeKind::kSphere:
      return v;
    case ShapeKind::kEllipsoid:
      g = local / (s.halfExtents * s.halfExtents);
      break;
    case ShapeKind::kCuboid: {
      const glm::dvec3 dent = s.halfExtents - glm::abs(local);
      const int axis = dent.x < dent.y ? (dent.x < dent.z ? 0 : 2) : (dent.y < dent.z ? 1 : 2);
      g[axis] = local[axis] < 0.0 ? -1.0 : 1.0;
      break;
    }
  }
  return s.axes * g;
}

// The segment from `node` along `dir` turned out of `shape` until its end is at most `depth` deep: in the
// plane of the segment and the shape's outward direction at `node`, so it ends as near its place as
// possible (as the cantilever styling turns its nodes out). The search is on the blend of the two
// directions (monotone in the angle, no trigonometry), to 1e-7 of the blend. `excessAtDir`: how much
// deeper than `depth` the end along `dir` is, as the caller found (> 0).
// (Moving the end radially out of a convex shape and aiming the segment at it never gets there: the
// aimed end falls short of the moved point, on the chord inside. The search starts at once.)
glm::dvec3 turnOut(const CollisionShape& shape, const glm::dvec3& node, const glm::dvec3& dir, double length,
                   double depth, double excessAtDir) {
  const glm::dvec3 out = glm::normalize(outward(shape, node));
  if (glm::dot(dir, out) < -0.999) return out;  // pointing straight in: straight out
  auto blend = [&](double u) { return glm::normalize(dir + u * (out - dir)); };
  auto excess = [&](double u) { return penetration(shape, node + length * blend(u)) - depth; };
  // The Illinois variant of regula falsi on the blend: a few evaluations where bisection takes twenty,
  // and the bracket keeps `hi` outside, which is what is returned.
  double lo = 0.0, hi = 1.0, flo = excessAtDir, fhi = excess(hi);
  if (fhi > 0.0) return out;
  int side = 0;
  for (int i = 0; i < 30 && hi - lo > 1e-7; ++i) {
    const double u = std::clamp((lo * fhi - hi * flo) / (fhi - flo), lo + 1e-9, hi - 1e-9), f = excess(u);
    if (f > 0.0) {
      lo = u;
      flo = f;
      if (side == -1) fhi *= 0.5;
      side = -1;
    } else {
      hi = u;
      fhi = f;
      if (side == 1) flo *= 0.5;
      side = 1;
    }
  }
  return blend(hi);
}

}  // namespace

double firstBendingFrequency(const Hairstyle& style, double length) {
  const double a = style.hairRadius1, b = style.hairRadius2;
  const double inertia = M_PI * a * b * b * b / 4.0, area = M_PI * a * b;
  const double l2 = length * length;
  return 1.875 * 1.875 * std::sqrt(style.young * inertia / (style.massDensity * area * l2 * l2)) /
         (2.0 * M_PI);
}

AnjyoHair::AnjyoHair(const Strands& rest, const Hairstyle& style, const Dynamics& dynamics,
                     const Collision& collision, uint64_t seed)
    : rest_(rest),
      restPoints_(rest.points),
      restAcceleration_(0.0, -style.gravity, 0.0),
      damping_(dynamics.damping),
      jointLimit_(glm::radians(style.jointLimit)),
      jointFrom_(style.jointLimitFrom),
      pseudoAlpha_(dynamics.pseudoAlpha),
      pseudoEpsilon_(dynamics.pseudoEpsilon),
      pseudoReach_(dynamics.pseudoReach),
      fluctuation_(dynamics.fluctuation),
      fluctuationEvery_(dynamics.fluctuationEvery),
      firstFrame_(dynamics.firstFrame),
      seed_(seed) {
  const size_t strands = rest.strandCount();
  firstSegment_.assign(strands + 1, 0);
  for (size_t s = 0; s < strands; ++s) {
    if (rest.pointsOf(s) == 0) throw InputError("guide " + std::to_string(s) + " has no points");
    firstSegment_[s + 1] = firstSegment_[s] + rest.pointsOf(s) - 1;
  }
  // Blocks of kLanes strands for stepLanes, each as long as its longest strand.
  const size_t blocks = (strands + kLanes - 1) / kLanes;
  blockFirst_.assign(blocks + 1, 0);
  for (size_t b = 0; b < blocks; ++b) {
    uint32_t most = 0;
    for (size_t s = b * kLanes; s < std::min(strands, (b + 1) * kLanes); ++s)
      most = std::max(most, firstSegment_[s + 1] - firstSegment_[s]);
    blockFirst_[b + 1] = blockFirst_[b] + most;
  }
  // At rest every angle is 0. The large arrays are made in huge pages on every core (huge_pages.h), and
  // filled strand by strand on every core: each strand's values depend on that strand alone.
  resizeLarge(state_, kStateHeader + blockFirst_.back() * kStateValues * kLanes);
  state_[0] = kStateTag;
  state_[1] = double(kLanes);
  state_[2] = double(kStateValues);
  resizeLarge(lanes_, blockFirst_.back());  // zeros past a strand's last segment
  resizeLarge(restForward_, rest.pointCount());
  restTangents_ = tangentsOf(rest);
  // posedInto writes the points and tangents; the rest's are kept apart, so that handing every other
  // attribute to a frame's guides copies no points.
  rest_.points = {};
  rest_.tangents = {};
  shapes_ = collision.shapes;
  for (size_t c = 0; c < shapes_.size() && head_ < 0; ++c)
    if (shapes_[c].kind == ShapeKind::kEllipsoid) head_ = int(c);
  auto laneOf = [&](size_t s, uint32_t j) -> LaneSegment& { return lanes_[blockFirst_[s / kLanes] + j]; };
  // Each segment's frame and length, and each strand's length; the first strand with a zero-length
  // segment, if any, is refused (the first, whatever the thread count).
  std::vector<double> totals(strands, 0.0);
  std::atomic<size_t> firstBad{strands};
  tbb::parallel_for(size_t(0), strands, [&](size_t s) {
    const uint32_t p0 = rest.firstPoint[s], k = firstSegment_[s + 1] - firstSegment_[s];
    double total = 0.0;
    for (uint32_t j = 0; j < k; ++j) {
      const glm::dvec3 a(rest.points[p0 + j]), b(rest.points[p0 + j + 1]);
      const double d = glm::length(b - a);
      if (!(d > 0.0)) {
        for (size_t seen = firstBad.load(); s < seen && !firstBad.compare_exchange_weak(seen, s);) {
        }
        return;
      }
      Segment segment{};
      segment.frame = frameFor((b - a) / d);
      segment.length = d;
      laneOf(s, j).set(s % kLanes, segment);
      total += d;
    }
    totals[s] = total;
  });
  if (firstBad < strands) {
    const size_t s = firstBad;
    const uint32_t p0 = rest.firstPoint[s];
    uint32_t j = 0;
    while (glm::length(glm::dvec3(rest.points[p0 + j + 1]) - glm::dvec3(rest.points[p0 + j])) > 0.0) ++j;
    throw InputError("guide " + std::to_string(s) + " has two points at the same place (points " +
                     std::to_string(j) + " and " + std::to_string(j + 1) + "); a segment needs a length");
  }
  const double longest = totals.empty() ? 0.0 : *std::max_element(totals.begin(), totals.end());
  const double frequency =
      dynamics.restFrequencyAuto ? firstBendingFrequency(style, longest) : dynamics.restFrequency;
  springOmega2_ = std::pow(2.0 * M_PI * frequency, 2);
  for (const CollisionShape& c : shapes_) {
    const double r = c.kind == ShapeKind::kSphere ? c.halfExtents.x
                     : c.kind == ShapeKind::kEllipsoid
                         ? std::max({c.halfExtents.x, c.halfExtents.y, c.halfExtents.z})
                         : glm::length(c.halfExtents);
    // Nothing farther than this from the centre is inside, or within the pseudo-force's reach.
    shapeReach2_.push_back(std::pow(r + std::max(dynamics.pseudoReach, 0.0), 2));
    // An ellipsoid's point p is inside when |A (p − centre)|² < 1, A its axes over its semi-axes; it is
    // beyond `reach` outside when that exceeds (1 + reach / smallest semi-axis)² (a bound, no roots).
    ShapeTest test;
    if (c.kind == ShapeKind::kEllipsoid) {
      for (int k = 0; k < 3; ++k) test.scaled[k] = c.axes[k] / c.halfExtents[k];
      const double smallest = std::min({c.halfExtents.x, c.halfExtents.y, c.halfExtents.z});
      test.near2 = std::pow(1.0 + std::max(dynamics.pseudoReach, 0.0) / smallest, 2);
      test.ellipsoid = true;
    }
    shapeTests_.push_back(test);
  }
  // Per strand: the inertias, the rest nodes as the recurrence will compute them, the turn allowed at
  // each node and each node's depth in each shape (what the motion is measured from).
  restDepth_.assign(shapes_.size(), std::vector<double>(rest.pointCount(), 0.0));
  tbb::parallel_for(size_t(0), strands, [&](size_t s) {
    const uint32_t p0 = rest.firstPoint[s], k = firstSegment_[s + 1] - firstSegment_[s];
    const size_t l = s % kLanes;
    // I_i = f (k/i)^p m_i d_i L/3, c_i = 1/I_i, u_i = d_i/2: c_i u_i m_i = 3 (i/k)^p / (2 f L). The tip
    // segment turns like the whole hair as one stick, as a single segment does (the compound pendulum),
    // and the inertia grows toward the root as 1/i (§3.2.1): at a given fraction of the length the
    // response is the same however finely the hair is cut into segments.
    for (uint32_t j = 0; j < k; ++j) {
      const double root = int(j) < dynamics.rootSegments ? dynamics.rootInertia : 1.0;
      LaneSegment& to = laneOf(s, j);
      to.coefficient[l] =
          3.0 * std::pow(double(j + 1) / double(k), dynamics.inertiaExponent) / (2.0 * root * totals[s]);
      to.springOverC[l] = springOmega2_ / to.coefficient[l];
    }
    glm::dvec3 node(rest.points[p0]);
    restForward_[p0] = node;
    glm::dvec3 before(0.0);
    for (uint32_t j = 0; j < k; ++j) {
      LaneSegment& to = laneOf(s, j);
      const Segment segment = to.at(l);
      const glm::dvec3 dir = directionAt(segment.frame, 0.0, 0.0);  // at rest
      const double restTurn = j > 0 ? std::acos(std::clamp(glm::dot(before, dir), -1.0, 1.0)) : 0.0;
      // The turn allowed at the node before segment i: JointAngleLimit from its node on, or the rest's.
      const bool limited = j > 0 && int(j) >= jointFrom_ && jointLimit_ < M_PI;
      const double allowed = limited ? std::max(jointLimit_, restTurn) : M_PI;
      to.cosAllowed[l] = limited ? std::cos(allowed) : -2.0;
      to.sinAllowed[l] = std::sin(allowed);
      node += segment.length * dir;
      restForward_[p0 + j + 1] = node;
      before = dir;
    }
    for (uint32_t p = p0; p < rest.firstPoint[s + 1]; ++p)
      for (size_t c = 0; c < shapes_.size(); ++c) restDepth_[c][p] = penetration(shapes_[c], restForward_[p]);
  });
  // The same points lane by lane, for posing.
  resizeLarge(lanePoints_, blockFirst_.back() + blocks);
  tbb::parallel_for(size_t(0), blocks, [&](size_t b) {
    for (size_t l = 0; l < kLanes; ++l) {
      const size_t s = std::min(b * kLanes + l, strands - 1);  // past the last strand: the last one's
      for (size_t j = 0; j <= blockFirst_[b + 1] - blockFirst_[b]; ++j) {
        const size_t p = rest.firstPoint[s] + std::min<size_t>(j, rest.pointsOf(s) - 1);
        LanePoint& to = lanePoints_[blockFirst_[b] + b + j];
        for (int c = 0; c < 3; ++c) {
          to.point[c][l] = rest.points[p][c];
          to.forward[c][l] = restForward_[p][c];
          to.tangent[c][l] = restTangents_[p][c];
        }
      }
    }
  });
}

AnjyoHair::Segment AnjyoHair::LaneSegment::at(size_t l) const {
  Segment s;
  for (int c = 0; c < 3; ++c) {
    s.frame.rest[c] = rest[c][l];
    s.frame.pole[c] = pole[c][l];
    s.frame.side[c] = side[c][l];
  }
  s.length = length[l];
  s.coefficient = coefficient[l];
  s.springOverC = springOverC[l];
  s.cosAllowed = cosAllowed[l];
  s.sinAllowed = sinAllowed[l];
  return s;
}

void AnjyoHair::LaneSegment::set(size_t l, const Segment& s) {
  for (int c = 0; c < 3; ++c) {
    rest[c][l] = s.frame.rest[c];
    pole[c][l] = s.frame.pole[c];
    side[c][l] = s.frame.side[c];
  }
  length[l] = s.length;
  coefficient[l] = s.coefficient;
  springOverC[l] = s.springOverC;
  cosAllowed[l] = s.cosAllowed;
  sinAllowed[l] = s.sinAllowed;
}

AnjyoHair::Segment AnjyoHair::segmentOf(size_t strand, uint32_t j) const {
  return lanes_[blockFirst_[strand / kLanes] + j].at(strand % kLanes);
}

bool AnjyoHair::fluctuates(int frame, bool firstSubstep) const {
  return firstSubstep && fluctuation_ > 0.0 && frame > firstFrame_ &&
         (frame - firstFrame_) % fluctuationEvery_ == 0;
}

void AnjyoHair::stepAndPose(const AccelerationField& field, double dt, int frame, bool firstSubstep,
                            const Pose& pose, Strands& out, Kernel kernel) {
  kernel = available(kernel);
  if (fluctuates(frame, firstSubstep) || kernel == Kernel::kStrands) {
    step(field, dt, frame, firstSubstep, kernel);
    posedInto(pose, out, kernel);
    return;
  }
  out.assignRestKeepingBuffers(rest_);
  tbb::parallel_for(size_t(0), blockFirst_.size() - 1,
                    [&](size_t b) { stepLanes(b * kLanes, field, dt, &pose, &out); });
}

void AnjyoHair::step(const AccelerationField& field, double dt, int frame, bool firstSubstep, Kernel kernel) {
  const bool fluctuate = fluctuates(frame, firstSubstep);
  kernel = available(kernel);
  if (fluctuate || kernel == Kernel::kStrands) {
    tbb::parallel_for(size_t(0), rest_.strandCount(),
                      [&](size_t s) { stepStrand(s, field, dt, frame, fluctuate); });
    return;
  }
  tbb::parallel_for(size_t(0), blockFirst_.size() - 1, [&](size_t b) { stepLanes(b * kLanes, field, dt); });
}

void AnjyoHair::stepStrand(size_t s, const AccelerationField& field, double dt, int frame, bool fluctuate) {
  const uint32_t p0 = rest_.firstPoint[s], first = firstSegment_[s], k = firstSegment_[s + 1] - first;
  const double keep = std::max(0.0, 1.0 - damping_ * dt), dt2 = dt * dt;
  const uint64_t block = fluctuate ? uint64_t((frame - firstFrame_) / fluctuationEvery_) : 0;
  const CollisionShape* head = head_ >= 0 ? &shapes_[size_t(head_)] : nullptr;
  glm::dvec3 node = restForward_[p0];  // the node this segment starts from, already placed this substep
  glm::dvec3 nodeVelocity(0.0);        // its velocity in the head's frame, for Coriolis
  glm::dvec3 newBefore(0.0);           // the direction just placed before this one
  for (uint32_t j = 0; j < k; ++j) {
    const Segment segment = segmentOf(s, j);
    const SegmentFrame& basis = segment.frame;
    double* state = &state_[stateAt(s, j)];  // value v at state[v * kLanes]
    auto value = [&](StateValue v) -> double& { return state[v * kLanes]; };
    const double theta0 = value(kTheta), phi0 = value(kPhi);
    double st, ct, sp, cp;
    sinCos(theta0, st, ct);
    sinCos(phi0, sp, cp);
    const glm::dvec3 across = cp * basis.rest + sp * basis.side;  // the longitude's horizontal direction
    const glm::dvec3 dir = ct * across + st * basis.pole;
    const glm::dvec3 thetaDir = -st * across + ct * basis.pole, phiDir = -sp * basis.rest + cp * basis.side;
    const double d = segment.length;
    glm::dvec3 departure = field.base - restAcceleration_;
    if (field.rotating) {
      // The segment's turn over the last step, to first order, gives its midpoint's velocity.
      const glm::dvec3 turnRate =
          ((theta0 - value(kThetaPrev)) * thetaDir + (phi0 - value(kPhiPrev)) * ct * phiDir) / dt;
      const glm::dvec3 mid = node + 0.5 * d * dir;
      departure = field.at(mid, nodeVelocity + 0.5 * d * turnRate) - restAcceleration_;
      nodeVelocity += d * turnRate;
    }
    // The departure from the styling load, scaled by ε near the head when it points into it (§3.2.2).
    if (head && pseudoEpsilon_ < 1.0 && departure != glm::dvec3(0.0)) {
      // Near: within the reach of the head's surface, measured along the ray from its centre in units of
      // its smallest semi-axis (|A v| < 1 + reach / smallest). D is the ellipsoid's gradient, Aᵀ A v.
      const ShapeTest& test = shapeTests_[size_t(head_)];
      const glm::dvec3 v = node - head->centre;
      const glm::dvec3 r(glm::dot(v, test.scaled[0]), glm::dot(v, test.scaled[1]),
                         glm::dot(v, test.scaled[2]));
      if (glm::dot(r, r) < test.near2) {
        const glm::dvec3 grad = r.x * test.scaled[0] + r.y * test.scaled[1] + r.z * test.scaled[2];
        if (glm::dot(grad, departure) < pseudoAlpha_ * glm::length(grad) * glm::length(departure))
          departure *= pseudoEpsilon_;
      }
    }
    // The spring toward the rest direction, as an acceleration the projective equations turn into
    // θ'' = −ω²θ for a small departure θ.
    const double c = segment.coefficient;
    const glm::dvec3 push = departure + segment.springOverC * (basis.rest - dir);
    const double thetaAcc = c * glm::dot(push, thetaDir);
    const double phiAcc = c * ct * glm::dot(push, phiDir);
    // (4)' and (5)', with the damping as a loss of the last step's motion.
    double theta = theta0 + keep * (theta0 - value(kThetaPrev)) + dt2 * thetaAcc;
    double phi = phi0 + keep * (phi0 - value(kPhiPrev)) + dt2 * phiAcc;
    if (fluctuate) {  // §3.2.3: a random turn, the most at the tip
      const double scale = fluctuation_ * double(j + 1) / double(k);
      theta += scale * (2.0 * counterUniform(seed_, s, kFluctuationKey ^ block, 2 * j) - 1.0);
      phi += scale * (2.0 * counterUniform(seed_, s, kFluctuationKey ^ block, 2 * j + 1) - 1.0);
    }
    double nst, nct, nsp, ncp;
    sinCos(theta, nst, nct);
    sinCos(phi, nsp, ncp);
    glm::dvec3 placed = nct * (ncp * basis.rest + nsp * basis.side) + nst * basis.pole;
    if (settle(segment, p0 + j + 1, node, newBefore, placed, theta, phi)) {
      sinCos(theta, nst, nct);
      sinCos(phi, nsp, ncp);
    }
    value(kThetaPrev) = theta0;
    value(kPhiPrev) = phi0;
    value(kTheta) = theta;
    value(kPhi) = phi;
    node += d * (nct * (ncp * basis.rest + nsp * basis.side) + nst * basis.pole);
    newBefore = placed;
  }
}

bool AnjyoHair::settle(const Segment& segment, size_t nodeIndex, const glm::dvec3& node,
                       const glm::dvec3& before, glm::dvec3& placed, double& theta, double& phi) const {
  const double d = segment.length;
  bool adjusted = false;
  // Out of every collision shape (no deeper than the node sat at rest), then the joint angle at the
  // node before this segment at most JointAngleLimit (or the rest's turn, §3.2.3). Where the two
  // disagree the limit wins: a hair does not kink to stay out.
  for (int pass = 0; pass < 3; ++pass) {
    bool moved = false;
    for (size_t c = 0; c < shapes_.size(); ++c) {
      if (!(shapes_[c].penalty > 0.0)) continue;  // a shape without penalty does not collide, as in grow
      const glm::dvec3 next = node + d * placed, v = next - shapes_[c].centre;
      if (glm::dot(v, v) >= shapeReach2_[c] || !shapeTests_[c].mayBeInside(v)) continue;
      const double allowedDepth = std::max(restDepth_[c][nodeIndex], 0.0);
      const double depth = penetration(shapes_[c], next);
      if (depth <= allowedDepth + 1e-9) continue;
      placed = turnOut(shapes_[c], node, placed, d, allowedDepth, depth - allowedDepth);
      moved = true;
    }
    const double cosTurn = glm::dot(before, placed);
    if (cosTurn < segment.cosAllowed - 1e-12) {
      glm::dvec3 side = placed - cosTurn * before;
      const double len = glm::length(side);
      side = len > 1e-12 ? side / len : segment.frame.pole;
      placed = segment.cosAllowed * before + segment.sinAllowed * side;
      moved = true;
    }
    adjusted = adjusted || moved;
    if (!moved) break;
  }
  if (adjusted) anglesNear(segment.frame, placed, theta, phi);
  return adjusted;
}

glm::dvec3 AnjyoHair::directionOf(size_t s, uint32_t j) const {
  const double* v = &state_[stateAt(s, j)];
  return directionAt(segmentOf(s, j).frame, v[kTheta * kLanes], v[kPhi * kLanes]);
}

std::array<double, AnjyoHair::kStateValues> AnjyoHair::segmentState(size_t s, uint32_t j) const {
  std::array<double, kStateValues> out;
  for (size_t v = 0; v < kStateValues; ++v) out[v] = state_[stateAt(s, j) + v * kLanes];
  return out;
}

void AnjyoHair::setSegmentState(size_t s, uint32_t j, const std::array<double, kStateValues>& values) {
  for (size_t v = 0; v < kStateValues; ++v) state_[stateAt(s, j) + v * kLanes] = values[v];
}

std::vector<glm::dvec3> AnjyoHair::nodes() const {
  std::vector<glm::dvec3> out(restPoints_.size());
  tbb::parallel_for(size_t(0), rest_.strandCount(), [&](size_t s) {
    const uint32_t p0 = rest_.firstPoint[s], first = firstSegment_[s], k = firstSegment_[s + 1] - first;
    glm::dvec3 node = restForward_[p0];
    out[p0] = node;
    for (uint32_t j = 0; j < k; ++j) {
      node += segmentOf(s, j).length * directionOf(s, j);
      out[p0 + j + 1] = node;
    }
  });
  return out;
}

Strands AnjyoHair::posed(const Pose& pose) const {
  Strands out;
  posedInto(pose, out);
  return out;
}

void AnjyoHair::posedInto(const Pose& pose, Strands& out, Kernel kernel) const {
  out.assignRestKeepingBuffers(rest_);  // every attribute but the points and tangents is the rest's
  kernel = available(kernel);
  if (kernel != Kernel::kStrands) {
    tbb::parallel_for(size_t(0), blockFirst_.size() - 1, [&](size_t b) { poseLanes(b * kLanes, pose, out); });
    return;
  }
  const bool still = pose.isIdentity();
  tbb::parallel_for(size_t(0), rest_.strandCount(), [&](size_t s) {
    const uint32_t p0 = rest_.firstPoint[s], first = firstSegment_[s], k = firstSegment_[s + 1] - first;
    glm::dvec3 node = restForward_[p0], dir(0.0);
    Segment segment{};   // the segment the point starts (the last point takes the last segment's)
    bool moved = false;  // whether it has left its rest direction
    for (uint32_t j = 0; j <= k; ++j) {
      const uint32_t p = p0 + j;
      if (j > 0) node += segment.length * dir;  // segment j − 1's
      if (j < k) {
        const double* v = &state_[stateAt(s, j)];
        segment = segmentOf(s, j);
        dir = directionAt(segment.frame, v[kTheta * kLanes], v[kPhi * kLanes]);
        moved = v[kTheta * kLanes] != 0.0 || v[kPhi * kLanes] != 0.0;
      }
      // The input point plus the motion: at rest exactly the input.
      out.points[p] = glm::vec3(pose.apply(glm::dvec3(restPoints_[p]) + (node - restForward_[p])));
      glm::dvec3 t(restTangents_[p]);
      // Turned with its segment: the minimal rotation from the rest direction to the current one.
      if (k > 0 && moved) t = transportFast(segment.frame.rest, dir, t);
      out.tangents[p] = glm::vec3(still ? t : pose.rotation * t);  // a rotation keeps it unit
    }
  });
}

void AnjyoHair::restore(const std::vector<double>& state, const std::string& source) {
  if (state.size() < kStateHeader || state[0] != kStateTag || state[1] != double(kLanes) ||
      state[2] != double(kStateValues))
    throw InputError({source, 0},
                     "its simulation state is not in the layout this hairgen keeps (an earlier "
                     "version, or another model's); simulate from the first frame");
  if (state.size() != state_.size())
    throw InputError({source, 0}, "its simulation state is for other guides (" +
                                      std::to_string(state.size()) + " values, these need " +
                                      std::to_string(state_.size()) +
                                      "); restart from a frame of the same guides");
  // Angles beyond kMaxAngle are not a shot's (16,000 turns) and past where sinCos is exact.
  for (size_t i = kStateHeader; i < state.size(); ++i)
    if (!(std::abs(state[i]) <= kMaxAngle))
      throw InputError({source, 0}, "its simulation state holds an angle that is not finite or beyond " +
                                        std::to_string(int(kMaxAngle)) +
                                        " rad; simulate from the first frame");
  state_ = state;
}

}  // namespace hairgen
