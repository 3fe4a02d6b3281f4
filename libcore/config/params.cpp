#include "libcore/config/params.h"

#include <cstdio>
#include <numeric>
#include <sstream>

#include "libcore/util/text.h"

namespace hairgen {
namespace {

std::string join(std::initializer_list<double> values) {
  std::string out;
  for (double v : values) out += (out.empty() ? "" : " ") + formatReal(v);
  return out;
}
std::string join(const glm::dvec3& v) {
  return join({v.x, v.y, v.z});
}

}  // namespace

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

std::string Config::canonicalText() const {
  std::ostringstream out;
  const Hairstyle& h = hairstyle;
  out << "Hairstyle.VisualityStep " << formatReal(h.visualityStep) << "\n"
      << "Hairstyle.CollisionStep " << formatReal(h.collisionStep) << "\n"
      << "Hairstyle.MaxIter " << h.maxIter << "\n"
      << "Hairstyle.Epsilon " << formatReal(h.epsilon) << "\n"
      << "Hairstyle.HairLengths";
  for (double l : h.hairLengths) out << " " << formatReal(l);
  out << "\n"
      << "Hairstyle.HairDensity " << formatReal(h.hairDensity) << "\n"
      << "Hairstyle.HairRadius1 " << formatReal(h.hairRadius1) << "\n"
      << "Hairstyle.HairRadius2 " << formatReal(h.hairRadius2) << "\n"
      << "Hairstyle.HelixRadius " << formatReal(h.helixRadius) << "\n"
      << "Hairstyle.HelixStep " << formatReal(h.helixStep) << "\n"
      << "Hairstyle.Poisson " << formatReal(h.poisson) << "\n"
      << "Hairstyle.Young " << formatReal(h.young) << "\n"
      << "Hairstyle.Density " << formatReal(h.density) << "\n"
      << "Hairstyle.Gravity " << formatReal(h.gravity) << "\n"
      << "Hairstyle.Model " << name(h.model) << "\n"
      << "Hairstyle.Clump " << formatReal(h.clump) << "\n"
      << "Hairstyle.StrayHairs " << (h.strayHairs ? "true" : "false") << "\n"
      << "Hairstyle.Seed " << h.seed << "\n"
      << "Hairstyle.Segments " << h.segments << "\n"
      << "Hairstyle.FlexuralRigidity " << formatReal(h.flexuralRigidity) << "\n"
      << "Hairstyle.JointAngleLimit " << formatReal(h.jointLimit) << " " << h.jointLimitFrom << "\n";
  for (const ForceField& f : h.forces)
    out << "Hairstyle.Force " << join(f.acceleration) << " " << int(f.region) << " " << formatReal(f.level)
        << " " << join(f.side) << " " << join(f.lo) << " " << join(f.hi) << "\n";
  for (const HairCut& c : h.cuts)
    out << "Hairstyle.Cut " << join({c.azimuthFrom, c.azimuthTo, c.zenithMax, c.height}) << "\n";
  for (const CollisionShape& c : collision.shapes) {
    out << "Collision." << name(c.kind) << " " << join({c.volume, c.penalty}) << " " << join(c.centre) << " "
        << join(c.halfExtents);
    if (c.kind != ShapeKind::kSphere)
      out << " " << join(c.axes[0]) << " " << join(c.axes[1]) << " " << join(c.axes[2]);
    out << "\n";
  }
  const Visuality& v = visuality;
  out << "Visuality.AmbientColor " << join(v.ambientColor) << "\n"
      << "Visuality.DiffuseColor " << join(v.diffuseColor) << "\n"
      << "Visuality.SpecularColor " << join(v.specularColor) << "\n"
      << "Visuality.Glossiness " << formatReal(v.glossiness) << "\n"
      << "Visuality.AmbientMean " << formatReal(v.ambientMean) << "\n"
      << "Visuality.AmbientDeviation " << formatReal(v.ambientDeviation) << "\n";
  const RenderSettings& r = render;
  out << "Render.Resolution " << r.resolution.x << " " << r.resolution.y << "\n"
      << "Render.CameraPosition " << join(r.cameraPosition) << "\n"
      << "Render.CameraTarget " << join(r.cameraTarget) << "\n"
      << "Render.CameraUp " << join(r.cameraUp) << "\n"
      << "Render.FieldOfView " << formatReal(r.fieldOfView) << "\n"
      << "Render.LightPosition " << join(r.lightPosition) << "\n"
      << "Render.LightColor " << join(r.lightColor) << "\n"
      << "Render.AmbientIntensity " << formatReal(r.ambientIntensity) << "\n"
      << "Render.Samples " << r.samples << "\n"
      << "Render.LayerSizes " << join({r.layerSizes.x, r.layerSizes.y, r.layerSizes.z, r.layerSizes.w})
      << "\n"
      << "Render.StrandOpacity " << formatReal(r.strandOpacity) << "\n"
      << "Render.StrandWidth " << formatReal(r.strandWidth) << "\n"
      << "Render.ShadingModel " << name(r.shadingModel) << "\n"
      << "Render.Background " << join(r.background) << "\n"
      << "Render.HeadColor " << join(r.headColor) << "\n"
      << "Render.VoxelSize " << formatReal(r.voxelSize) << "\n"
      << "Render.VolumePadding " << r.volumePadding << "\n"
      << "Render.ShellDensity " << formatReal(r.shellDensity) << "\n"
      << "Render.VolumetricBlend " << formatReal(r.volumetricBlend) << "\n";
  return out.str();
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
