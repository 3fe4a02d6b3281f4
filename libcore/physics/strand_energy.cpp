// Energy of a static Super-Helix with penalty collisions, thesis §4.1.1.3 and §4.1.2.
#include "libcore/physics/strand_energy.h"

#include <cmath>
#include <numeric>
#include <stdexcept>
#include <type_traits>

namespace hairgen {

template <class T>
T penetrationOf(const CollisionShape& shape, const Vec3<T>& p) {
  const Vec3<T> v = p - Vec3<T>(shape.centre);
  const Vec3<T> local(dotOf(v, shape.axes[0]), dotOf(v, shape.axes[1]), dotOf(v, shape.axes[2]));
  const glm::dvec3& half = shape.halfExtents;
  switch (shape.kind) {
    case ShapeKind::kSphere:
      return half.x - lengthOf(v);
    case ShapeKind::kEllipsoid: {
      // Along the ray from the centre through p: the surface lies at dist / ratio (§4.1.2.1.1).
      const T dist = lengthOf(local);
      const T ratio = lengthOf(Vec3<T>(local.x / half.x, local.y / half.y, local.z / half.z));
      if (!(ratio > 0.0)) return T(std::min(half.x, std::min(half.y, half.z)));
      return dist / ratio - dist;
    }
    case ShapeKind::kCuboid: {
      // |local| per axis; a face's dent has the derivative of the coordinate it is measured along.
      auto dent = [&](int k) { return valueOf(local[k]) < 0.0 ? half[k] + local[k] : half[k] - local[k]; };
      return minOf(dent(0), minOf(dent(1), dent(2)));
    }
  }
  return T(0.0);
}
template double penetrationOf(const CollisionShape&, const Vec3<double>&);
template EnergyGradient penetrationOf(const CollisionShape&, const Vec3<EnergyGradient>&);

namespace {

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

}  // namespace

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
    double reach = boundingRadius(s) + std::max(extra, 0.0);
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

template <class T>
T StrandEnergy::penalty(const Vec3<T>& p) const {
  // penetration() per kind (equal to it within rounding), with the cheap rejections first.
  using std::sqrt;
  T sum(0.0);
  for (const Shape& shape : shapes_) {
    const Vec3<T> v = p - Vec3<T>(shape.shape.centre);
    const T dist2 = dotOf(v, v);
    if (dist2 >= shape.reach2) continue;
    T dent;
    if (shape.shape.kind == ShapeKind::kEllipsoid) {
      const Vec3<T> scaled(dotOf(v, shape.scaledAxes[0]), dotOf(v, shape.scaledAxes[1]),
                           dotOf(v, shape.scaledAxes[2]));
      const T ratio2 = dotOf(scaled, scaled);
      if (ratio2 >= shape.ratio2Outside) continue;
      if (!(ratio2 > 0.0)) {
        dent = penetrationOf(shape.shape, p);
      } else {
        const T dist = sqrt(dist2);  // |local| = |v|: the axes are orthonormal
        dent = dist / sqrt(ratio2) - dist;
      }
    } else if (shape.shape.kind == ShapeKind::kSphere) {
      dent = shape.shape.halfExtents.x - sqrt(dist2);
    } else {
      dent = penetrationOf(shape.shape, p);
    }
    const T d = dent + shape.extra;
    if (d > 0.0) sum += 0.5 * shape.shape.penalty * d * d;
  }
  return sum;
}

template <class T>
void StrandEnergy::accumulate(std::span<const T> q, size_t first, const RodFrame& start, T& elastic,
                              T& height, T& penalty) const {
  for (size_t k = first; k < lengths_.size(); ++k) {
    const T dt = q[3 * k] - rest_.tau, d1 = q[3 * k + 1] - rest_.kappa1, d2 = q[3 * k + 2] - rest_.kappa2;
    elastic += lengths_[k] * (bend1_ * d1 * d1 + bend2_ * d2 * d2 + twist_ * dt * dt);
  }
  // One walk along the rod gives both the height integral (§4.1.1.3.2, closed form per element) and
  // the collision samples (two sin/cos pairs per element, whatever the number of samples).
  // With derivatives, a sample that touches no shape (penalty and derivatives 0) is found from its
  // position's value alone.
  constexpr bool kValues = std::is_same_v<T, double>;
  auto element = [&](const BasicHelixElement<T>& e, double, size_t i) {
    height += e.length() * (e.start().position.y - root_.position.y) + e.displacementIntegral().y;
    // An element's samples lie within its length of its start (the arc is at least the chord): where no
    // shape reaches that far, each would add exactly 0, so none is placed.
    if (shapes_.empty() || !mayTouch(valueOf(e.start().position), e.length())) return;
    const ElementSamples& samples = samples_[first + i];
    e.visitGrid(samples.first, collisionStep_, samples.gridCount,
                [&](size_t, double u, const T& c, const T& s) {
                  if (kValues || this->penalty(e.valueAt(u, valueOf(c), valueOf(s))) > 0.0)
                    penalty += this->penalty(e.at(u, c, s));
                });
    for (double u : samples.offGrid)
      if (kValues || this->penalty(e.valuePosition(u)) > 0.0) penalty += this->penalty(e.position(u));
  };
  forEachElement(BasicRodFrame<T>(start), std::span(lengths_).subspan(first), q.subspan(3 * first), element);
}

EnergyTerms StrandEnergy::terms(std::span<const double> q) const {
  double elastic = 0.0, height = 0.0, penalty = 0.0;
  accumulate(q, 0, root_, elastic, height, penalty);
  return {elastic, weight_ * height, penalty * collisionStep_};
}

double StrandEnergy::valueAndGradient(std::span<const double> q, std::span<double> gradient) const {
  if (q.size() != 3 * lengths_.size() || gradient.size() != q.size())
    throw std::invalid_argument("valueAndGradient: q and gradient need 3 coordinates per element");
  // Forward mode: each walk seeds kGradientWidth coordinates and carries their derivatives. The
  // elements before the first seeded coordinate's do not depend on it, so a walk starts there,
  // from that element's start frame (found in doubles); the first walk, from the root, gives the value.
  std::vector<EnergyGradient> dual(q.begin(), q.end());
  double value = 0.0;
  RodFrame start = root_;
  size_t startElement = 0;
  for (size_t first = 0; first < q.size(); first += kGradientWidth) {
    const size_t end = std::min(q.size(), first + kGradientWidth), element = first / 3;
    for (size_t i = 0; i < q.size(); ++i)
      dual[i] = i >= first && i < end ? EnergyGradient::variable(q[i], int(i - first)) : EnergyGradient(q[i]);
    for (; startElement < element; ++startElement) {
      const double* e = &q[3 * startElement];
      start = advance(start, darbouxVector(start, e[0], e[1], e[2]), lengths_[startElement]);
    }
    EnergyGradient elastic(0.0), height(0.0), penalty(0.0);
    accumulate(std::span<const EnergyGradient>(dual), element, start, elastic, height, penalty);
    const EnergyGradient total = elastic + weight_ * height + penalty * collisionStep_;
    for (size_t i = first; i < end; ++i) gradient[i] = total.d[i - first];
    if (first == 0) value = total.v;
  }
  return value;
}

}  // namespace hairgen
