// Energy of a static Super-Helix with penalty collisions, thesis §4.1.1.3 and §4.1.2.
#include "libcore/physics/strand_energy.h"

#include <array>
#include <cmath>
#include <numeric>
#include <stdexcept>

namespace hairgen {

double penetration(const CollisionShape& shape, const glm::dvec3& p) {
  const glm::dvec3 v = p - shape.centre;
  const glm::dvec3 local(glm::dot(v, shape.axes[0]), glm::dot(v, shape.axes[1]), glm::dot(v, shape.axes[2]));
  const glm::dvec3& half = shape.halfExtents;
  switch (shape.kind) {
    case ShapeKind::kSphere:
      return half.x - glm::length(v);
    case ShapeKind::kEllipsoid: {
      // Along the ray from the centre through p: the surface lies at dist / ratio (§4.1.2.1.1).
      const double dist = glm::length(local);
      const double ratio = glm::length(glm::dvec3(local.x / half.x, local.y / half.y, local.z / half.z));
      if (!(ratio > 0.0)) return std::min(half.x, std::min(half.y, half.z));
      return dist / ratio - dist;
    }
    case ShapeKind::kCuboid: {
      // |local| per axis; a face's dent has the derivative of the coordinate it is measured along.
      auto dent = [&](int k) { return local[k] < 0.0 ? half[k] + local[k] : half[k] - local[k]; };
      return std::min(dent(0), std::min(dent(1), dent(2)));
    }
  }
  return 0.0;
}

double boundingRadius(const CollisionShape& shape) {
  switch (shape.kind) {
    case ShapeKind::kSphere:
      return shape.halfExtents.x;
    case ShapeKind::kEllipsoid:
      return std::max(shape.halfExtents.x, std::max(shape.halfExtents.y, shape.halfExtents.z));
    case ShapeKind::kCuboid:
      return glm::length(shape.halfExtents);
  }
  return 0.0;
}

StrandEnergy::StrandEnergy(const Hairstyle& style, const Collision& collision, const RodFrame& root,
                           double envelope)
    : lengths_(style.hairLengths),
      root_(root),
      rest_(restShape(style.helixRadius, style.helixStep)),
      collisionStep_(style.collisionStep) {
  const double a = style.hairRadius1, b = style.hairRadius2;
  const double i1 = M_PI * a * b * b * b / 4.0, i2 = M_PI * b * a * a * a / 4.0;
  const double j = M_PI * a * b * (a * a + b * b) / 4.0;
  const double mu = style.young / (2.0 * (1.0 + style.poisson));
  bend1_ = 0.5 * style.young * i1;
  bend2_ = 0.5 * style.young * i2;
  twist_ = 0.5 * mu * j;
  weight_ = style.massDensity * M_PI * a * b * style.gravity;
  for (const CollisionShape& s : collision.shapes) {
    if (!(s.penalty > 0.0)) continue;
    double extra = s.envelopeGrowth * envelope;
    // A cuboid's envelope is the box grown by `extra` on every face, whose corner is farther out than
    // its bounding sphere's growth.
    double reach = s.kind == ShapeKind::kCuboid ? glm::length(s.halfExtents + std::max(extra, 0.0))
                                                : boundingRadius(s) + std::max(extra, 0.0);
    Shape shape{s, extra, reach, reach * reach, {}, HUGE_VAL};
    if (s.kind == ShapeKind::kEllipsoid) {
      for (int k = 0; k < 3; ++k) shape.scaledAxes[k] = s.axes[k] / s.halfExtents[k];
      double minHalf = std::min(s.halfExtents.x, std::min(s.halfExtents.y, s.halfExtents.z));
      double ratio = 1.0 + std::max(extra, 0.0) / minHalf;
      shape.ratio2Outside = ratio * ratio;
    }
    shapes_.push_back(shape);
  }
  if (shapes_.empty()) return;

  // Samples every CollisionStep after the root, the last at the tip; each belongs to the element
  // it ends in (a sample on a joint to the earlier element).
  std::vector<double> s = sampleArcLengths(style.totalLength(), collisionStep_, false);
  samples_.resize(lengths_.size());
  size_t i = 0;
  double elementStart = 0.0;
  for (size_t k = 0; k < lengths_.size(); ++k) {
    const double l = lengths_[k];
    const bool last = k + 1 == lengths_.size();
    ElementSamples& out = samples_[k];
    for (; i < s.size() && (s[i] <= elementStart + l || last); ++i) {
      double u = std::min(s[i] - elementStart, l);
      if (out.gridCount == 0) {
        out.first = u;
        out.gridCount = 1;
      } else if (out.offGrid.empty() &&
                 std::abs(u - (out.first + static_cast<double>(out.gridCount) * collisionStep_)) < 1e-12) {
        ++out.gridCount;
      } else {
        out.offGrid.push_back(u);
      }
    }
    elementStart += l;
  }
  walkedElements_.reserve(lengths_.size());
  touchingSamples_.reserve(s.size());
}

std::vector<double> StrandEnergy::restCoordinates() const {
  std::vector<double> q;
  for (size_t e = 0; e < lengths_.size(); ++e) q.insert(q.end(), {rest_.tau, rest_.kappa1, rest_.kappa2});
  return q;
}

double StrandEnergy::energyScale() const {
  double length = std::accumulate(lengths_.begin(), lengths_.end(), 0.0);
  return 0.5 * weight_ * length * length + 2.0 * bend1_ / length;
}

std::vector<double> StrandEnergy::initialSteps() const {
  std::vector<double> steps;
  for (double l : lengths_) steps.insert(steps.end(), {0.25 / l, 0.25 / l, 0.25 / l});
  return steps;
}

std::vector<double> StrandEnergy::inverseStiffness() const {
  std::vector<double> out;
  for (double l : lengths_)
    out.insert(out.end(), {0.5 / (l * twist_), 0.5 / (l * bend1_), 0.5 / (l * bend2_)});
  return out;
}

bool StrandEnergy::mayTouch(const glm::dvec3& p, double radius) const {
  for (const Shape& shape : shapes_) {
    const glm::dvec3 v = p - shape.shape.centre;
    const double within = shape.reach + radius;
    if (glm::dot(v, v) < within * within) return true;
  }
  return false;
}

template <bool kKeepWalk>
void StrandEnergy::accumulate(std::span<const double> q, double& elastic, double& height,
                              double& penalty) const {
  for (size_t k = 0; k < lengths_.size(); ++k) {
    const double dt = q[3 * k] - rest_.tau, d1 = q[3 * k + 1] - rest_.kappa1,
                 d2 = q[3 * k + 2] - rest_.kappa2;
    elastic += lengths_[k] * (bend1_ * d1 * d1 + bend2_ * d2 * d2 + twist_ * dt * dt);
  }
  // One walk along the rod gives both the height integral (§4.1.1.3.2, closed form per element) and
  // the collision samples (two sin/cos pairs per element, whatever the number of samples). Kept for
  // valueAndGradient's walk back: each element, and each sample that touches a shape with its force.
  if constexpr (kKeepWalk) {
    walkedElements_.resize(lengths_.size());
    touchingSamples_.clear();
  }
  auto sample = [&](double u, double cosX, double sinX, const glm::dvec3& p) {
    if constexpr (!kKeepWalk) {
      penalty += this->penalty(p);
      return;
    }
    glm::dvec3 force;
    penalty += this->penalty(p, &force);
    if (force != glm::dvec3(0.0)) touchingSamples_.push_back({u, cosX, sinX, p, collisionStep_ * force});
  };
  auto element = [&](const HelixElement& e, double, size_t i) {
    const glm::dvec3 integral = e.displacementIntegral();
    height += e.length() * (e.start().position.y - root_.position.y) + integral.y;
    const size_t firstSample = touchingSamples_.size();
    // An element's samples lie within its length of its start (the arc is at least the chord): where no
    // shape reaches that far, each would add exactly 0, so none is placed.
    if (!shapes_.empty() && mayTouch(e.start().position, e.length())) {
      const ElementSamples& samples = samples_[i];
      e.visitGrid(samples.first, collisionStep_, samples.gridCount,
                  [&](size_t, double u, double c, double s) { sample(u, c, s, e.at(u, c, s)); });
      for (double u : samples.offGrid) {
        const double x = e.omega() * u;
        sample(u, kKeepWalk ? std::cos(x) : 1.0, kKeepWalk ? std::sin(x) : 0.0, e.position(u));
      }
    }
    if constexpr (kKeepWalk)
      walkedElements_[i] = {e.start(),     e.end().position, integral,    e.omega(),
                            e.cosLength(), e.sinLength(),    firstSample, touchingSamples_.size()};
  };
  forEachElement(root_, std::span(lengths_), q, element);
}

EnergyTerms StrandEnergy::terms(std::span<const double> q) const {
  double elastic = 0.0, height = 0.0, penalty = 0.0;
  accumulate<false>(q, elastic, height, penalty);
  return {elastic, weight_ * height, penalty * collisionStep_};
}

double StrandEnergy::penalty(const glm::dvec3& p, glm::dvec3* gradient) const {
  // penetration() per kind (equal to it within rounding), with the cheap rejections first; with
  // `gradient`, each shape's ∂/∂p beside it.
  double sum = 0.0;
  if (gradient) *gradient = glm::dvec3(0.0);
  for (const Shape& shape : shapes_) {
    const glm::dvec3 v = p - shape.shape.centre;
    const double dist2 = glm::dot(v, v);
    if (dist2 >= shape.reach2) continue;
    double dent;
    glm::dvec3 slope(0.0);  // ∂dent/∂p
    if (shape.shape.kind == ShapeKind::kEllipsoid) {
      const glm::dvec3 scaled(glm::dot(v, shape.scaledAxes[0]), glm::dot(v, shape.scaledAxes[1]),
                              glm::dot(v, shape.scaledAxes[2]));
      const double ratio2 = glm::dot(scaled, scaled);
      if (ratio2 >= shape.ratio2Outside) continue;
      if (!(ratio2 > 0.0)) {
        dent = penetration(shape.shape, p);  // at the centre: the smallest semi-axis, flat
      } else {
        const double dist = std::sqrt(dist2);  // |local| = |v|: the axes are orthonormal
        const double ratio = std::sqrt(ratio2);
        dent = dist / ratio - dist;
        // dent = |v|/ρ − |v|, ρ = |A v|: ∇ = (1/ρ − 1) v/|v| − |v|/ρ³ AᵀA v.
        if (gradient) {
          const glm::dvec3 stretched = scaled.x * shape.scaledAxes[0] + scaled.y * shape.scaledAxes[1] +
                                       scaled.z * shape.scaledAxes[2];
          slope = (1.0 / ratio - 1.0) / dist * v - dist / (ratio2 * ratio) * stretched;
        }
      }
    } else if (shape.shape.kind == ShapeKind::kSphere) {
      const double dist = std::sqrt(dist2);
      dent = shape.shape.halfExtents.x - dist;
      if (gradient && dist > 0.0) slope = -v / dist;
    } else {
      dent = penetration(shape.shape, p);
      if (gradient) {
        // The nearest face's: dent = half − |local| along its axis (the first of equals, as std::min
        // picks).
        const glm::dvec3 local(glm::dot(v, shape.shape.axes[0]), glm::dot(v, shape.shape.axes[1]),
                               glm::dot(v, shape.shape.axes[2]));
        const glm::dvec3 dents = shape.shape.halfExtents - glm::abs(local);
        const int inner = dents[2] < dents[1] ? 2 : 1, axis = dents[inner] < dents[0] ? inner : 0;
        slope = (local[axis] < 0.0 ? 1.0 : -1.0) * shape.shape.axes[axis];
      }
    }
    const double d = dent + shape.extra;
    if (d > 0.0) {
      sum += 0.5 * shape.shape.penalty * d * d;
      if (gradient) *gradient += shape.shape.penalty * d * slope;
    }
  }
  return sum;
}

namespace {

// The slopes of a helix element's coefficients in Ω, over Ω (smooth at Ω = 0): with x = Ω u,
//   β = (∂b/∂Ω)/Ω = (u Ω sin x − 2(1 − cos x))/Ω⁴,     b = (1 − cos x)/Ω²,
//   γ = (∂c/∂Ω)/Ω = (u Ω (1 − cos x) − 3(x − sin x))/Ω⁵, c = (x − sin x)/Ω³,
// and for the integral of c over an element of length u, ic = (x²/2 − 1 + cos x)/Ω⁴,
//   ι = (∂ic/∂Ω)/Ω = (u Ω (x − sin x) − 4(x²/2 − 1 + cos x))/Ω⁶.
// Below kSlopeSeriesBelow their Taylor series, u^(k+2) Σ_{n≥1} (−1)^n 2n x^(2n−2)/(2n+k)! for k = 2, 3
// and 4, where the closed forms cancel (to 1e-16 at the threshold with seven terms).
constexpr double kSlopeSeriesBelow = 0.5;
static_assert(kSlopeSeriesBelow >= kHelixSeriesBelow, "a slope's closed form reads cos and sin of Ω u");

// The series' coefficients, term n − 1 of row k − 2: (−1)^n 2n/(2n+k)!.
constexpr std::array<std::array<double, 7>, 3> kSlopeSeries = [] {
  std::array<std::array<double, 7>, 3> terms{};
  for (int k = 2; k <= 4; ++k)
    for (int n = 1; n <= 7; ++n) {
      double factorial = 1.0;
      for (int i = 2; i <= 2 * n + k; ++i) factorial *= i;
      terms[size_t(k - 2)][size_t(n - 1)] = (n % 2 ? -1.0 : 1.0) * 2.0 * n / factorial;
    }
  return terms;
}();

double slopeSeries(double x2, int k) {
  const std::array<double, 7>& terms = kSlopeSeries[size_t(k - 2)];
  double sum = terms[6];
  for (int n = 5; n >= 0; --n) sum = sum * x2 + terms[size_t(n)];
  return sum;
}

struct Slopes {
  double beta, gamma;
};
[[gnu::always_inline]] inline Slopes helixSlopes(double omega, double u, double cosX, double sinX) {
  const double x = omega * u, u2 = u * u;
  if (std::abs(x) < kSlopeSeriesBelow) {
    const double x2 = x * x;
    return {u2 * u2 * slopeSeries(x2, 2), u2 * u2 * u * slopeSeries(x2, 3)};
  }
  const double o2 = omega * omega, o4 = o2 * o2;
  return {(u * omega * sinX - 2.0 * (1.0 - cosX)) / o4,
          (u * omega * (1.0 - cosX) - 3.0 * (x - sinX)) / (o4 * omega)};
}
double integralSlope(double omega, double l, double cosX, double sinX) {
  const double x = omega * l, l2 = l * l;
  if (std::abs(x) < kSlopeSeriesBelow) return l2 * l2 * l2 * slopeSeries(x * x, 4);
  const double o2 = omega * omega;
  return (l * omega * (x - sinX) - 4.0 * (0.5 * x * x - 1.0 + cosX)) / (o2 * o2 * o2);
}
// ic (above) itself, with its series below kHelixSeriesBelow as displacementIntegral takes it.
double integralOfC(double omega, double l, double cosX) {
  const double x = omega * l, l4 = l * l * l * l;
  if (std::abs(x) < kHelixSeriesBelow) {
    const double x2 = x * x;
    return l4 * (1.0 / 24.0 - x2 / 720.0 * (1.0 - x2 / 56.0 * (1.0 - x2 / 90.0)));
  }
  const double o2 = omega * omega;
  return (0.5 * x * x - 1.0 + cosX) / (o2 * o2);
}

// ∂/∂q of g · d, where d = s e0 + b (q × e0) + c q × (q × e0) is a point of an element in its start frame
// (e0 its tangent, q its Darboux vector there: (τ, κ1, κ2)), g a vector in that frame, and β, γ the
// slopes of b and c (helixSlopes). With a = q × e0 and m = q × a = q q_x − |q|² e0:
//   ∂(g·d)/∂q = β (g·a) q + b (e0 × g) + γ (g·m) q + c (q_x g + (g·q) e0 − 2 g_x q).
[[gnu::always_inline]] inline glm::dvec3 pointSlope(const glm::dvec3& g, const glm::dvec3& q,
                                                    const glm::dvec3& a, const glm::dvec3& m, double b,
                                                    double c, double beta, double gamma) {
  const glm::dvec3 e0xg(0.0, -g.z, g.y);
  const glm::dvec3 mixed = q.x * g + glm::dvec3(glm::dot(g, q), 0.0, 0.0) - 2.0 * g.x * q;
  return (beta * glm::dot(g, a) + gamma * glm::dot(g, m)) * q + b * e0xg + c * mixed;
}

}  // namespace

double StrandEnergy::valueAndGradient(std::span<const double> q, std::span<double> gradient) const {
  if (q.size() != 3 * lengths_.size() || gradient.size() != q.size())
    throw std::invalid_argument("valueAndGradient: q and gradient need 3 coordinates per element");
  // The value as operator() takes it (accumulate, the same sums in the same order: the same bits), the
  // walk up kept; the elastic term's gradient is its own, element by element.
  const size_t elements = lengths_.size();
  for (size_t k = 0; k < elements; ++k) {
    const double l2 = 2.0 * lengths_[k];
    gradient[3 * k] = l2 * twist_ * (q[3 * k] - rest_.tau);
    gradient[3 * k + 1] = l2 * bend1_ * (q[3 * k + 1] - rest_.kappa1);
    gradient[3 * k + 2] = l2 * bend2_ * (q[3 * k + 2] - rest_.kappa2);
  }
  double elastic = 0.0, height = 0.0, penalty = 0.0;
  accumulate<true>(q, elastic, height, penalty);
  const double value = elastic + weight_ * height + penalty * collisionStep_;

  // The walk back. A change of element i's coordinates bends element i and moves everything after it
  // rigidly with i's end frame: by its end's displacement δE and a turn δω about E. So what lies beyond
  // i enters i's gradient through the sum of its forces F (· ∂E/∂q) and their torque T about E
  // (· ∂ω/∂q), gathered element by element from the tip. In i's start frame, with x = Ω ℓ:
  //   E = ℓ e0 + b(ℓ) a + c(ℓ) m (pointSlope), ∂ω/∂q = J = ℓ I + b(ℓ)[q]× + c(ℓ)[q]×² (SO(3)'s left
  //   Jacobian of the element's turn ℓ q, times ℓ), so T · J δq = (ℓ T − b q × T + c q × (q × T)) · δq.
  // Gravity is a force of w per metre along the strand (w = ρ S g, upward gradient): the element's own
  // enters through its displacement integral ∫(r − r(0)) = ℓ²/2 e0 + c(ℓ) a + ic m.
  const glm::dvec3 lift(0.0, weight_, 0.0);
  glm::dvec3 force(0.0), torque(0.0);  // beyond element i, and its torque about i's end
  for (size_t i = elements; i-- > 0;) {
    const WalkedElement& walked = walkedElements_[i];
    const RodFrame& frame = walked.start;
    auto local = [&](const glm::dvec3& v) {
      return glm::dvec3(glm::dot(v, frame.n0), glm::dot(v, frame.n1), glm::dot(v, frame.n2));
    };
    const glm::dvec3 darboux(q[3 * i], q[3 * i + 1], q[3 * i + 2]);
    // Ω as the walk up took it (|W| in world axes), so each closed form takes the branch it took there.
    const double omega = walked.omega, invOmega = omega > 0.0 ? 1.0 / omega : 0.0, l = lengths_[i];
    const glm::dvec3 a(0.0, darboux.z, -darboux.y),
        m = darboux.x * darboux - glm::dot(darboux, darboux) * glm::dvec3(1.0, 0.0, 0.0);
    const double cosL = walked.cosLength, sinL = walked.sinLength;  // read where x ≥ kHelixSeriesBelow
    const HelixCoefficients atEnd = helixCoefficients(omega, invOmega, l, cosL, sinL);
    const Slopes endSlopes = helixSlopes(omega, l, cosL, sinL);
    const glm::dvec3 torqueHere = local(torque);
    glm::dvec3 slope =
        pointSlope(local(force), darboux, a, m, atEnd.b, atEnd.c, endSlopes.beta, endSlopes.gamma);
    slope += l * torqueHere - atEnd.b * glm::cross(darboux, torqueHere) +
             atEnd.c * glm::cross(darboux, glm::cross(darboux, torqueHere));
    slope += pointSlope(local(lift), darboux, a, m, atEnd.c, integralOfC(omega, l, cosL), endSlopes.gamma,
                        integralSlope(omega, l, cosL, sinL));
    for (size_t s = walked.firstSample; s < walked.endSample; ++s) {
      const TouchingSample& sample = touchingSamples_[s];
      const HelixCoefficients k = helixCoefficients(omega, invOmega, sample.u, sample.cosX, sample.sinX);
      const Slopes sampleSlopes = helixSlopes(omega, sample.u, sample.cosX, sample.sinX);
      slope +=
          pointSlope(local(sample.force), darboux, a, m, k.b, k.c, sampleSlopes.beta, sampleSlopes.gamma);
    }
    for (int c = 0; c < 3; ++c) gradient[3 * i + size_t(c)] += slope[c];
    // What lies beyond element i − 1: element i's own forces, and the torque moved to i's start.
    torque += glm::cross(walked.end - frame.position, force);
    for (size_t s = walked.firstSample; s < walked.endSample; ++s) {
      const TouchingSample& sample = touchingSamples_[s];
      force += sample.force;
      torque += glm::cross(sample.position - frame.position, sample.force);
    }
    force += l * lift;
    torque += glm::cross(walked.integral, lift);
  }
  return value;
}

}  // namespace hairgen
