// Energy of a static Super-Helix with penalty collisions, thesis §4.1.1.3 and §4.1.2.
#include "libcore/strand_energy.h"

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
      if (!(ratio > 0.0)) return std::min(shape.halfExtents.x, std::min(shape.halfExtents.y, shape.halfExtents.z));
      return dist / ratio - dist;
    }
    case ShapeKind::kCuboid: {
      glm::dvec3 dent = shape.halfExtents - glm::abs(local);
      return std::min(dent.x, std::min(dent.y, dent.z));
    }
  }
  return 0.0;
}

StrandEnergy::StrandEnergy(const Hairstyle& style, const Collision& collision, const RodFrame& root, double envelope)
    : lengths_(style.hairLengths), root_(root), rest_(restShape(style.helixRadius, style.helixStep)),
      collisionStep_(style.collisionStep) {
  const double a = style.hairRadius1, b = style.hairRadius2;
  const double i1 = M_PI * a * b * b * b / 4.0, i2 = M_PI * b * a * a * a / 4.0;
  const double j = M_PI * a * b * (a * a + b * b) / 4.0;
  const double mu = style.young / (2.0 * (1.0 + style.poisson));
  bend1_ = 0.5 * style.young * i1;
  bend2_ = 0.5 * style.young * i2;
  twist_ = 0.5 * mu * j;
  weight_ = style.density * M_PI * a * b * style.gravity;
  for (const CollisionShape& s : collision.shapes)
    if (s.penalty > 0.0) shapes_.push_back({s, s.volume * envelope});
  if (!shapes_.empty()) samples_ = sampleArcLengths(style.totalLength(), style.collisionStep, false);
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

EnergyTerms StrandEnergy::terms(std::span<const double> q) const {
  EnergyTerms e;
  for (size_t k = 0; k < lengths_.size(); ++k) {
    double dt = q[3 * k] - rest_.tau, d1 = q[3 * k + 1] - rest_.kappa1, d2 = q[3 * k + 2] - rest_.kappa2;
    e.elastic += lengths_[k] * (bend1_ * d1 * d1 + bend2_ * d2 * d2 + twist_ * dt * dt);
  }
  if (weight_ != 0.0) e.gravity = weight_ * heightIntegral(root_, lengths_, q);
  if (!shapes_.empty()) {
    // Walk the samples element by element; within an element each collision step is the same rigid
    // motion, so positions follow by one rotation and one translation per sample (no trig).
    double penalty = 0.0;
    RodFrame start = root_;
    double elementStart = 0.0;
    size_t i = 0;
    for (size_t k = 0; k < lengths_.size(); ++k) {
      const double l = lengths_[k];
      const glm::dvec3 w = darbouxVector(start, q[3 * k], q[3 * k + 1], q[3 * k + 2]);
      const bool last = k + 1 == lengths_.size();
      if (i < samples_.size() && (samples_[i] <= elementStart + l || last)) {
        RodFrame f = advance(start, w, std::min(samples_[i] - elementStart, l));
        // One collision step as a rotation R about w and a displacement in the element's start frame.
        RodFrame unit{glm::dvec3(0.0), start.n0, start.n1, start.n2};
        RodFrame stepped = advance(unit, w, collisionStep_);
        glm::dmat3 toStart(start.n0, start.n1, start.n2), atStep(stepped.n0, stepped.n1, stepped.n2);
        glm::dmat3 rotation = atStep * glm::transpose(toStart);
        glm::dvec3 displacement = stepped.position;
        glm::dmat3 current = glm::dmat3(f.n0, f.n1, f.n2) * glm::transpose(toStart);
        glm::dvec3 p = f.position;
        double s = samples_[i];
        while (true) {
          for (const Shape& shape : shapes_) {
            double d = penetration(shape.shape, p) + shape.extra;
            if (d > 0.0) penalty += 0.5 * shape.shape.penalty * d * d;
          }
          ++i;
          if (i >= samples_.size() || (samples_[i] > elementStart + l && !last)) break;
          double next = samples_[i];
          if (std::abs(next - s - collisionStep_) > 1e-12) {  // the shorter last interval
            RodFrame g = advance(start, w, std::min(next - elementStart, l));
            p = g.position;
            current = glm::dmat3(g.n0, g.n1, g.n2) * glm::transpose(toStart);
          } else {
            p += current * displacement;
            current = rotation * current;
          }
          s = next;
        }
      }
      start = advance(start, w, l);
      elementStart += l;
    }
    e.collision = penalty * collisionStep_;
  }
  return e;
}

}  // namespace hairgen
