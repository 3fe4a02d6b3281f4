#include "libcore/config/params.h"

#include <cmath>
#include <numeric>
#include <sstream>
#include <stdexcept>

#include "libcore/util/fnv.h"
#include "libcore/util/text.h"

namespace hairgen {

const char* name(StylingModel model) {
  return model == StylingModel::kCantilever ? "cantilever" : "superhelix";
}

const char* name(Minimiser minimiser) {
  return minimiser == Minimiser::kBfgs ? "bfgs" : "rosenbrock";
}

const char* name(ShadingModel model) {
  switch (model) {
    case ShadingModel::kThesis:
      return "thesis";
    case ShadingModel::kAnjyo:
      return "anjyo";
    case ShadingModel::kVolumetric:
      return "volumetric";
    case ShadingModel::kKajiyaKay:
      break;
  }
  return "kajiya-kay";
}

const char* name(DynamicsModel model) {
  return model == DynamicsModel::kSprings ? "springs" : "anjyo";
}

const char* name(ShapeKind kind) {
  switch (kind) {
    case ShapeKind::kEllipsoid:
      return "Ellipsoid";
    case ShapeKind::kCuboid:
      return "Cuboid";
    case ShapeKind::kSphere:
      break;
  }
  return "Sphere";
}

const CollisionShape* headShape(const Collision& collision) {
  for (const CollisionShape& s : collision.shapes)
    if (s.fitted) return &s;
  for (const CollisionShape& s : collision.shapes)
    if (s.kind == ShapeKind::kEllipsoid) return &s;
  return nullptr;
}

bool ForceField::contains(const glm::dvec3& p) const {
  switch (region) {
    case Region::kAll:
      return true;
    case Region::kAbove:
      return p.y > level;
    case Region::kBelow:
      return p.y < level;
    case Region::kSide:
      return glm::dot(p, side) > 0.0;
    case Region::kBox:
      return glm::all(glm::greaterThanEqual(p, lo)) && glm::all(glm::lessThanEqual(p, hi));
  }
  return false;
}

glm::dvec3 RootFlow::at(const glm::dvec3& root) const {
  if (fitted && !resolved)
    throw std::logic_error("RootFlow away-from auto read before the head's whorl was found (fitRootFlow)");
  if (kind == Kind::kAwayFrom) {
    const glm::dvec3 d = root - value;
    return glm::length(d) > 0.0 ? glm::normalize(d) : glm::dvec3(0.0);
  }
  return value;
}

glm::dvec3 Hairstyle::growDirection(const glm::dvec3& root, const glm::dvec3& normal) const {
  const glm::dvec3 n = glm::normalize(normal);
  if (rootTilt <= 0.0) return n;
  // The flow projected onto the scalp's tangent plane; where it is along the normal, no lean.
  const glm::dvec3 flow = rootFlow.at(root), along = flow - glm::dot(flow, n) * n;
  if (glm::length(along) < 1e-6) return n;
  const double tilt = glm::radians(rootTilt);
  return std::cos(tilt) * n + std::sin(tilt) * glm::normalize(along);
}

double Hairstyle::totalLength() const {
  return std::accumulate(hairLengths.begin(), hairLengths.end(), 0.0);
}

std::string Config::digest() const {
  return formatDigest(fnv1a(canonicalText()));
}

}  // namespace hairgen
