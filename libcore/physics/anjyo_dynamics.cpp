// Anjyo et al. 1992 §3, as anjyo_dynamics.h describes it.
#include "libcore/physics/anjyo_dynamics.h"

#include <algorithm>
#include <cmath>

#include <tbb/parallel_for.h>

#include "libcore/physics/strand_energy.h"
#include "libcore/util/error.h"
#include "libcore/util/random.h"

namespace hairgen {
namespace {

constexpr uint64_t kFluctuationKey = 0x666c756374ull;  // "fluct": apart from every other stream

SegmentFrame frameFor(const glm::dvec3& rest) {
  // A pole across the segment: horizontal where it can be, so that for hanging hair θ swings it in
  // its vertical plane and φ about the vertical.
  glm::dvec3 pole = glm::cross(rest, glm::dvec3(0.0, 1.0, 0.0));
  if (glm::length(pole) < 0.1) pole = glm::cross(rest, glm::dvec3(1.0, 0.0, 0.0));
  pole = glm::normalize(pole);
  return {rest, pole, glm::cross(pole, rest)};
}

// sin and cos of a segment's θ and φ: its direction and the two perpendicular unit vectors of the
// paper's θ and φ planes follow from them without further trigonometry.
struct Trig {
  double sl, cl, sp, cp;  // sin and cos of the latitude θ and the longitude φ
};
Trig trig(double theta, double phi) {
  return {std::sin(theta), std::cos(theta), std::sin(phi), std::cos(phi)};
}
glm::dvec3 direction(const SegmentFrame& b, const Trig& t) {
  return t.cl * (t.cp * b.rest + t.sp * b.side) + t.sl * b.pole;
}
glm::dvec3 thetaVector(const SegmentFrame& b, const Trig& t) {  // ∂direction/∂θ
  return -t.sl * (t.cp * b.rest + t.sp * b.side) + t.cl * b.pole;
}
glm::dvec3 phiVector(const SegmentFrame& b, const Trig& t) {
  return -t.sp * b.rest + t.cp * b.side;
}  // ⊥ projection

// The (θ, φ) of unit `dir` nearest to a segment's previous angles: past the pole the same direction is
// (±π − θ, φ + π), and φ is unwrapped, so the recurrences see no jump.
void anglesNear(const SegmentFrame& b, const glm::dvec3& dir, double& theta, double& phi) {
  const double lat = std::asin(std::clamp(glm::dot(dir, b.pole), -1.0, 1.0));
  const double x = glm::dot(dir, b.rest), y = glm::dot(dir, b.side);
  const double lon = std::hypot(x, y) > 1e-12 ? std::atan2(y, x) : phi;
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
// plane of the segment and the shape's outward direction at `node`, by bisection on the turn, so it
// ends as near its place as possible (as the cantilever styling turns its nodes out).
glm::dvec3 turnOut(const CollisionShape& shape, const glm::dvec3& node, const glm::dvec3& dir, double length,
                   double depth) {
  const glm::dvec3 out = glm::normalize(outward(shape, node));
  const double cosAngle = std::clamp(glm::dot(dir, out), -1.0, 1.0), angle = std::acos(cosAngle);
  glm::dvec3 across = out - cosAngle * dir;
  if (glm::length(across) < 1e-12) return out;  // pointing straight in: straight out
  across = glm::normalize(across);
  auto turned = [&](double t) { return std::cos(t) * dir + std::sin(t) * across; };
  if (penetration(shape, node + length * turned(angle)) > depth) return out;
  double lo = 0.0, hi = angle;
  for (int i = 0; i < 40; ++i) {
    const double mid = 0.5 * (lo + hi);
    (penetration(shape, node + length * turned(mid)) > depth ? lo : hi) = mid;
  }
  return turned(hi);
}

}  // namespace

SegmentFrame AnjyoHair::basisOf(size_t i) const {
  return {restDir_[i], pole_[i], side_[i]};
}

AccelerationField headFrameField(const HeadState& head, const glm::dvec3& wind, double gravity) {
  AccelerationField f;
  const glm::dmat3 toHead = glm::transpose(head.pose.rotation);
  f.base = toHead * (glm::dvec3(0.0, -gravity, 0.0) + wind - head.acceleration);
  f.omega = toHead * head.omega;
  f.alpha = toHead * head.alpha;
  f.centre = head.pose.centre;
  f.rotating = f.omega != glm::dvec3(0.0) || f.alpha != glm::dvec3(0.0);
  return f;
}

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
  for (size_t s = 0; s < strands; ++s)
    firstSegment_[s + 1] = firstSegment_[s] + std::max(rest.pointsOf(s), 1u) - 1;
  const size_t segments = firstSegment_.back();
  theta_.assign(segments, 0.0);
  phi_.assign(segments, 0.0);
  restDir_.resize(segments);
  pole_.resize(segments);
  side_.resize(segments);
  length_.resize(segments);
  coefficient_.resize(segments);
  restTurn_.assign(segments, 0.0);
  restForward_.resize(rest.pointCount());
  shapes_ = collision.shapes;
  for (size_t c = 0; c < shapes_.size() && head_ < 0; ++c)
    if (shapes_[c].kind == ShapeKind::kEllipsoid) head_ = int(c);
  double longest = 0.0;
  for (size_t s = 0; s < strands; ++s) {
    const uint32_t p0 = rest.firstPoint[s], k = firstSegment_[s + 1] - firstSegment_[s];
    double total = 0.0;
    for (uint32_t j = 0; j < k; ++j) {
      const glm::dvec3 a(rest.points[p0 + j]), b(rest.points[p0 + j + 1]);
      const double d = glm::length(b - a);
      if (!(d > 0.0))
        throw InputError("guide " + std::to_string(s) + " has two points at the same place (points " +
                         std::to_string(j) + " and " + std::to_string(j + 1) + "); a segment needs a length");
      const size_t i = firstSegment_[s] + j;
      const SegmentFrame basis = frameFor((b - a) / d);
      restDir_[i] = basis.rest;
      pole_[i] = basis.pole;
      side_[i] = basis.side;
      length_[i] = d;
      total += d;
    }
    longest = std::max(longest, total);
    // I_i = f (k/i)^p m_i d_i L/3, c_i = 1/I_i, u_i = d_i/2: c_i u_i m_i = 3 (i/k)^p / (2 f L). The tip
    // segment turns like the whole hair as one stick, as a single segment does (the compound pendulum),
    // and the inertia grows toward the root as 1/i (§3.2.1): at a given fraction of the length the
    // response is the same however finely the hair is cut into segments.
    for (uint32_t j = 0; j < k; ++j) {
      const size_t i = firstSegment_[s] + j;
      const double root = int(j) < dynamics.rootSegments ? dynamics.rootInertia : 1.0;
      coefficient_[i] =
          3.0 * std::pow(double(j + 1) / double(k), dynamics.inertiaExponent) / (2.0 * root * total);
    }
  }
  thetaPrev_ = theta_;
  phiPrev_ = phi_;
  const double frequency =
      dynamics.restFrequencyAuto ? firstBendingFrequency(style, longest) : dynamics.restFrequency;
  springOmega2_ = std::pow(2.0 * M_PI * frequency, 2);
  // The rest nodes as the recurrence will compute them, the turn at each node and each node's depth in
  // each shape: what the motion is measured from.
  restDepth_.assign(shapes_.size(), std::vector<double>(rest.pointCount(), 0.0));
  for (size_t s = 0; s < strands; ++s) {
    const uint32_t p0 = rest.firstPoint[s], k = firstSegment_[s + 1] - firstSegment_[s];
    glm::dvec3 node(rest.points[p0]);
    restForward_[p0] = node;
    glm::dvec3 before(0.0);
    for (uint32_t j = 0; j < k; ++j) {
      const size_t i = firstSegment_[s] + j;
      const glm::dvec3 dir = direction(basisOf(i), trig(0.0, 0.0));
      if (j > 0) restTurn_[i] = std::acos(std::clamp(glm::dot(before, dir), -1.0, 1.0));
      node += length_[i] * dir;
      restForward_[p0 + j + 1] = node;
      before = dir;
    }
    for (uint32_t p = p0; p < rest.firstPoint[s + 1]; ++p)
      for (size_t c = 0; c < shapes_.size(); ++c) restDepth_[c][p] = penetration(shapes_[c], restForward_[p]);
  }
}

void AnjyoHair::step(const AccelerationField& field, double dt, int frame, bool firstSubstep) {
  const bool fluctuate = firstSubstep && fluctuation_ > 0.0 && frame > firstFrame_ &&
                         (frame - firstFrame_) % fluctuationEvery_ == 0;
  tbb::parallel_for(size_t(0), rest_.strandCount(),
                    [&](size_t s) { stepStrand(s, field, dt, frame, fluctuate); });
}

void AnjyoHair::stepStrand(size_t s, const AccelerationField& field, double dt, int frame, bool fluctuate) {
  const uint32_t p0 = rest_.firstPoint[s], first = firstSegment_[s], k = firstSegment_[s + 1] - first;
  const double keep = std::max(0.0, 1.0 - damping_ * dt), dt2 = dt * dt;
  const uint64_t block = fluctuate ? uint64_t((frame - firstFrame_) / fluctuationEvery_) : 0;
  const CollisionShape* head = head_ >= 0 ? &shapes_[size_t(head_)] : nullptr;
  glm::dvec3 node = restForward_[p0], nodeBefore = node;  // this substep's and the last one's
  glm::dvec3 newBefore(0.0);                              // the direction just placed before this one
  for (uint32_t j = 0; j < k; ++j) {
    const size_t i = first + j;
    const SegmentFrame basis = basisOf(i);
    const Trig now = trig(theta_[i], phi_[i]);
    const glm::dvec3 dir = direction(basis, now);
    const glm::dvec3 mid = node + 0.5 * length_[i] * dir;
    glm::dvec3 velocity(0.0);
    if (field.rotating) {  // the segment's midpoint's velocity in the head's frame, for Coriolis
      const glm::dvec3 before = direction(basis, trig(thetaPrev_[i], phiPrev_[i]));
      velocity = (mid - (nodeBefore + 0.5 * length_[i] * before)) / dt;
      nodeBefore += length_[i] * before;
    }
    // The departure from the styling load, scaled by ε near the head when it points into it (§3.2.2).
    glm::dvec3 departure = field.at(mid, velocity) - restAcceleration_;
    if (head && pseudoEpsilon_ < 1.0 && departure != glm::dvec3(0.0) &&
        penetration(*head, node) > -pseudoReach_) {
      const glm::dvec3 d = outward(*head, node);
      if (glm::dot(d, departure) < pseudoAlpha_ * glm::length(d) * glm::length(departure))
        departure *= pseudoEpsilon_;
    }
    // The spring toward the rest direction, as an acceleration the projective equations turn into
    // θ'' = −ω²θ for a small departure θ.
    const double c = coefficient_[i];
    const glm::dvec3 push = departure + (springOmega2_ / c) * (basis.rest - dir);
    const double thetaAcc = c * glm::dot(push, thetaVector(basis, now));
    const double phiAcc = c * now.cl * glm::dot(push, phiVector(basis, now));
    // (4)' and (5)', with the damping as a loss of the last step's motion.
    double theta = theta_[i] + keep * (theta_[i] - thetaPrev_[i]) + dt2 * thetaAcc;
    double phi = phi_[i] + keep * (phi_[i] - phiPrev_[i]) + dt2 * phiAcc;
    if (fluctuate) {  // §3.2.3: a random turn, the most at the tip
      const double scale = fluctuation_ * double(j + 1) / double(k);
      theta += scale * (2.0 * counterUniform(seed_, s, kFluctuationKey ^ block, 2 * j) - 1.0);
      phi += scale * (2.0 * counterUniform(seed_, s, kFluctuationKey ^ block, 2 * j + 1) - 1.0);
    }
    glm::dvec3 placed = direction(basis, trig(theta, phi));
    bool adjusted = false;
    // Out of every collision shape (no deeper than the node sat at rest), then the joint angle at the
    // node before this segment at most JointAngleLimit (or the rest's turn, §3.2.3). Where the two
    // disagree the limit wins: a hair does not kink to stay out.
    const bool limited = j > 0 && int(j) >= jointFrom_ && jointLimit_ < M_PI;
    for (int pass = 0; pass < 3; ++pass) {
      bool moved = false;
      for (size_t c2 = 0; c2 < shapes_.size(); ++c2) {
        if (!(shapes_[c2].penalty > 0.0)) continue;  // a shape without penalty does not collide, as in grow
        const glm::dvec3 next = node + length_[i] * placed;
        const double allowedDepth = std::max(restDepth_[c2][p0 + j + 1], 0.0);
        if (penetration(shapes_[c2], next) <= allowedDepth + 1e-9) continue;
        placed = turnOut(shapes_[c2], node, placed, length_[i], allowedDepth);
        moved = true;
      }
      if (limited) {
        const double allowed = std::max(jointLimit_, restTurn_[i]);
        const double cosTurn = std::clamp(glm::dot(newBefore, placed), -1.0, 1.0);
        if (std::acos(cosTurn) > allowed + 1e-12) {
          glm::dvec3 across = placed - cosTurn * newBefore;
          const double len = glm::length(across);
          across = len > 1e-12 ? across / len : basis.pole;
          placed = std::cos(allowed) * newBefore + std::sin(allowed) * across;
          moved = true;
        }
      }
      adjusted = adjusted || moved;
      if (!moved) break;
    }
    const glm::dvec3 next = node + length_[i] * placed;
    if (adjusted) anglesNear(basis, placed, theta, phi);
    thetaPrev_[i] = theta_[i];
    phiPrev_[i] = phi_[i];
    theta_[i] = theta;
    phi_[i] = phi;
    node = next;
    newBefore = placed;
  }
}

std::vector<glm::dvec3> AnjyoHair::nodes() const {
  std::vector<glm::dvec3> out(rest_.pointCount());
  for (size_t s = 0; s < rest_.strandCount(); ++s) {
    const uint32_t p0 = rest_.firstPoint[s], first = firstSegment_[s], k = firstSegment_[s + 1] - first;
    glm::dvec3 node = restForward_[p0];
    out[p0] = node;
    for (uint32_t j = 0; j < k; ++j) {
      const size_t i = first + j;
      node += length_[i] * direction(basisOf(i), trig(theta_[i], phi_[i]));
      out[p0 + j + 1] = node;
    }
  }
  return out;
}

Strands AnjyoHair::posed(const Pose& pose) const {
  Strands out = rest_;
  const std::vector<glm::dvec3> now = nodes();
  const std::vector<glm::vec3> restTangents = tangentsOf(rest_);
  out.tangents.resize(out.pointCount());
  for (size_t s = 0; s < rest_.strandCount(); ++s) {
    const uint32_t p0 = rest_.firstPoint[s], first = firstSegment_[s], k = firstSegment_[s + 1] - first;
    for (uint32_t j = 0; j <= k; ++j) {
      const uint32_t p = p0 + j;
      // The input point plus the motion: at rest exactly the input.
      out.points[p] = glm::vec3(pose.apply(glm::dvec3(rest_.points[p]) + (now[p] - restForward_[p])));
      glm::dvec3 t(restTangents[p]);
      const size_t i = first + std::min(j, k - 1);
      if (k > 0 && (theta_[i] != 0.0 || phi_[i] != 0.0)) {
        // Turned with its segment: the minimal rotation from the rest direction to the current one.
        const glm::dvec3 a = restDir_[i], b = direction(basisOf(i), trig(theta_[i], phi_[i]));
        const glm::dvec3 axis = glm::cross(a, b);
        const double sinAngle = glm::length(axis), cosAngle = glm::dot(a, b);
        if (sinAngle > 1e-15) {
          const glm::dvec3 u = axis / sinAngle;
          t = t * cosAngle + glm::cross(u, t) * sinAngle + u * glm::dot(u, t) * (1.0 - cosAngle);
        }
      }
      out.tangents[p] = pose.isIdentity() ? glm::vec3(t) : glm::vec3(glm::normalize(pose.rotation * t));
    }
  }
  return out;
}

std::vector<double> AnjyoHair::state() const {
  std::vector<double> out;
  out.reserve(theta_.size() * 4);
  for (size_t i = 0; i < theta_.size(); ++i)
    out.insert(out.end(), {theta_[i], phi_[i], thetaPrev_[i], phiPrev_[i]});
  return out;
}

void AnjyoHair::restore(const std::vector<double>& state, const std::string& source) {
  if (state.size() != theta_.size() * 4)
    throw InputError({source, 0}, "its simulation state has " + std::to_string(state.size() / 4) +
                                      " segments, the guides " + std::to_string(theta_.size()) +
                                      "; restart from a frame of the same guides");
  for (size_t i = 0; i < theta_.size(); ++i) {
    theta_[i] = state[4 * i];
    phi_[i] = state[4 * i + 1];
    thetaPrev_[i] = state[4 * i + 2];
    phiPrev_[i] = state[4 * i + 3];
    if (!std::isfinite(theta_[i] + phi_[i] + thetaPrev_[i] + phiPrev_[i]))
      throw InputError({source, 0}, "its simulation state holds a non-finite angle");
  }
}

}  // namespace hairgen
