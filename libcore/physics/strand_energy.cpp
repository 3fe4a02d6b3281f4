// Energy of a static Super-Helix with penalty collisions, thesis §4.1.1.3 and §4.1.2.
#include "libcore/physics/strand_energy.h"

#include <cmath>
#include <numeric>

namespace hairgen {

double penetration(const CollisionShape& shape, const glm::dvec3& p) {
  glm::dvec3 v = p - shape.centre;
  glm::dvec3 local(glm::dot(v, shape.axes[0]), glm::dot(v, shape.axes[1]), glm::dot(v, shape.axes[2]));
  switch (shape.kind) {
    case ShapeKind::kSphere:
      return shape.halfExtents.x - glm::length(v);
    case ShapeKind::kEllipsoid: {
      // Along the ray from the centre through p: the surface lies at dist / ratio (§4.1.2.1.1).
      double dist = glm::length(local);
      double ratio = glm::length(local / shape.halfExtents);
      if (!(ratio > 0.0))
        return std::min(shape.halfExtents.x, std::min(shape.halfExtents.y, shape.halfExtents.z));
      return dist / ratio - dist;
    }
    case ShapeKind::kCuboid: {
      glm::dvec3 dent = shape.halfExtents - glm::abs(local);
      return std::min(dent.x, std::min(dent.y, dent.z));
    }
  }
  return 0.0;
}

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

bool StrandEnergy::mayTouch(const glm::dvec3& p, double radius) const {
  for (const Shape& shape : shapes_) {
    const glm::dvec3 v = p - shape.shape.centre;
    const double within = shape.reach + radius;
    if (glm::dot(v, v) < within * within) return true;
  }
  return false;
}

double StrandEnergy::penalty(const glm::dvec3& p) const {
  // penetration() per kind (equal to it within rounding), with the cheap rejections first.
  double sum = 0.0;
  for (const Shape& shape : shapes_) {
    const glm::dvec3 v = p - shape.shape.centre;
    const double dist2 = glm::dot(v, v);
    if (dist2 >= shape.reach2) continue;
    double dent;
    if (shape.shape.kind == ShapeKind::kEllipsoid) {
      glm::dvec3 scaled(glm::dot(v, shape.scaledAxes[0]), glm::dot(v, shape.scaledAxes[1]),
                        glm::dot(v, shape.scaledAxes[2]));
      const double ratio2 = glm::dot(scaled, scaled);
      if (ratio2 >= shape.ratio2Outside) continue;
      if (!(ratio2 > 0.0)) {
        dent = penetration(shape.shape, p);
      } else {
        const double dist = std::sqrt(dist2);  // |local| = |v|: the axes are orthonormal
        dent = dist / std::sqrt(ratio2) - dist;
      }
    } else if (shape.shape.kind == ShapeKind::kSphere) {
      dent = shape.shape.halfExtents.x - std::sqrt(dist2);
    } else {
      dent = penetration(shape.shape, p);
    }
    double d = dent + shape.extra;
    if (d > 0.0) sum += 0.5 * shape.shape.penalty * d * d;
  }
  return sum;
}

EnergyTerms StrandEnergy::terms(std::span<const double> q) const {
  EnergyTerms e;
  for (size_t k = 0; k < lengths_.size(); ++k) {
    double dt = q[3 * k] - rest_.tau, d1 = q[3 * k + 1] - rest_.kappa1, d2 = q[3 * k + 2] - rest_.kappa2;
    e.elastic += lengths_[k] * (bend1_ * d1 * d1 + bend2_ * d2 * d2 + twist_ * dt * dt);
  }
  // One walk along the rod gives both the height integral (§4.1.1.3.2, closed form per element) and
  // the collision samples (two sin/cos pairs per element, whatever the number of samples).
  double height = 0.0, penalty = 0.0;
  forEachElement(root_, lengths_, q, [&](const HelixElement& element, double, size_t k) {
    height +=
        element.length() * (element.start().position.y - root_.position.y) + element.displacementIntegral().y;
    // An element's samples lie within its length of its start (the arc is at least the chord): where no
    // shape reaches that far, each would add exactly 0, so none is placed.
    if (shapes_.empty() || !mayTouch(element.start().position, element.length())) return;
    const ElementSamples& samples = samples_[k];
    element.visitGrid(samples.first, collisionStep_, samples.gridCount,
                      [&](size_t, const glm::dvec3& p) { penalty += this->penalty(p); });
    for (double u : samples.offGrid) penalty += this->penalty(element.position(u));
  });
  e.gravity = weight_ * height;
  e.collision = penalty * collisionStep_;
  return e;
}

}  // namespace hairgen
