#include "libcore/config/params.h"

#include <cstdio>
#include <numeric>
#include <sstream>

#include "libcore/util/text.h"

namespace hairgen {

const char* name(StylingModel model) {
  return model == StylingModel::kCantilever ? "cantilever" : "superhelix";
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

double Hairstyle::totalLength() const {
  return std::accumulate(hairLengths.begin(), hairLengths.end(), 0.0);
}

std::string Config::digest() const {
  std::string text = canonicalText();
  uint64_t hash = 0xcbf29ce484222325ull;  // FNV-1a, 64 bit
  for (unsigned char c : text) {
    hash ^= c;
    hash *= 0x100000001b3ull;
  }
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(hash));
  return hex;
}

}  // namespace hairgen
