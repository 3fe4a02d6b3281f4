#include "libcore/config/setup.h"

#include <algorithm>
#include <cmath>

#include "libcore/util/text.h"

namespace hairgen {
namespace {

constexpr double kBig = 1e300;

// Builds the frame of an Ellipsoid or Cuboid from the three axis vectors of its config line:
// normalised and made orthogonal (Gram-Schmidt in the given order), right-handed.
glm::dmat3 orthonormalAxes(const SectionReader& reader, const ConfigLine& line, glm::dvec3 u, glm::dvec3 v,
                           glm::dvec3 w) {
  double scale = std::max(glm::length(u), std::max(glm::length(v), glm::length(w)));
  if (glm::length(u) < 1e-9 || glm::length(v) < 1e-9 || glm::length(w) < 1e-9)
    throw reader.error(
        line,
        "'" + line.key + "': an axis vector is zero; give three independent axes, e.g. 1 0 0 0 1 0 0 0 1");
  u = glm::normalize(u);
  v -= glm::dot(v, u) * u;
  if (glm::length(v) < 1e-6 * scale)
    throw reader.error(line, "'" + line.key + "': the second axis is parallel to the first");
  v = glm::normalize(v);
  glm::dvec3 n = glm::cross(u, v);
  if (std::abs(glm::dot(glm::normalize(w), n)) < 1e-6)
    throw reader.error(line, "'" + line.key + "': the third axis lies in the plane of the first two");
  return glm::dmat3(u, v, glm::dot(w, n) < 0.0 ? -n : n);
}

CollisionShape readShape(const SectionReader& reader, const ConfigLine& line, ShapeKind kind) {
  size_t count = kind == ShapeKind::kSphere ? 6 : 17;
  if (line.values.size() != count)
    throw reader.error(
        line, "'" + line.key + "' takes " + std::to_string(count) + " values, found " +
                  std::to_string(line.values.size()) + "; expected " +
                  (kind == ShapeKind::kSphere ? "volume penalty cx cy cz r"
                                              : "volume penalty cx cy cz a b c ux uy uz vx vy vz wx wy wz"));
  CollisionShape shape;
  shape.kind = kind;
  shape.where = line.where;
  shape.volume = reader.checkReal(line, 0, {}, "volume");
  shape.penalty = reader.checkReal(line, 1, Range::nonNegative(), "penalty");
  for (int i = 0; i < 3; ++i) shape.centre[i] = reader.checkReal(line, 2 + i, {}, "centre");
  if (kind == ShapeKind::kSphere) {
    shape.halfExtents = glm::dvec3(reader.checkReal(line, 5, Range::positive(), "radius"));
    return shape;
  }
  for (int i = 0; i < 3; ++i)
    shape.halfExtents[i] = reader.checkReal(line, 5 + i, Range::positive(), "dimension");
  glm::dvec3 axis[3];
  for (int a = 0; a < 3; ++a)
    for (int i = 0; i < 3; ++i) axis[a][i] = reader.checkReal(line, 8 + 3 * a + i, {}, "axis");
  shape.axes = orthonormalAxes(reader, line, axis[0], axis[1], axis[2]);
  return shape;
}

ForceField readForce(const SectionReader& r, const ConfigLine& line) {
  auto bad = [&](const std::string& why) {
    return r.error(
        line, "Force " + why +
                  "; expected ax ay az all | above Y | below Y | side +x|-x|+z|-z | box x0 y0 z0 x1 y1 z1");
  };
  if (line.values.size() < 4) throw bad("needs an acceleration and a region");
  ForceField f;
  f.where = line.where;
  for (int i = 0; i < 3; ++i)
    f.acceleration[i] = r.checkReal(line, i, Range::closed(-1e4, 1e4), "acceleration");
  const std::string region = toLower(line.values[3]);
  const size_t extra = line.values.size() - 4;
  if (region == "all" && extra == 0) {
    f.region = ForceField::Region::kAll;
  } else if ((region == "above" || region == "below") && extra == 1) {
    f.region = region == "above" ? ForceField::Region::kAbove : ForceField::Region::kBelow;
    f.level = r.checkReal(line, 4, {}, "height");
  } else if (region == "side" && extra == 1) {
    const std::string& s = line.values[4];
    f.region = ForceField::Region::kSide;
    if (s == "+x")
      f.side = {1, 0, 0};
    else if (s == "-x")
      f.side = {-1, 0, 0};
    else if (s == "+z")
      f.side = {0, 0, 1};
    else if (s == "-z")
      f.side = {0, 0, -1};
    else
      throw bad("side '" + s + "' is not +x, -x, +z or -z");
  } else if (region == "box" && extra == 6) {
    f.region = ForceField::Region::kBox;
    for (int i = 0; i < 3; ++i) f.lo[i] = r.checkReal(line, 4 + i, {}, "box corner");
    for (int i = 0; i < 3; ++i) f.hi[i] = r.checkReal(line, 7 + i, {}, "box corner");
  } else {
    throw bad("region '" + line.values[3] + "' with " + std::to_string(extra) + " values is not understood");
  }
  return f;
}

ConfigText emptyText(const std::filesystem::path& setupFile, const char* what) {
  return ConfigText{std::string("(no ") + what + " file; defaults)", setupFile.parent_path(), {}};
}

void requireExisting(const PathRef& ref, const char* key) {
  std::error_code ec;
  if (!std::filesystem::exists(ref.path, ec))
    throw InputError(ref.where,
                     std::string(key) + " names '" + ref.path.string() +
                         "', which does not exist (paths are relative to the file that names them)");
  if (std::filesystem::is_directory(ref.path, ec))
    throw InputError(ref.where,
                     std::string(key) + " names '" + ref.path.string() + "', which is a directory");
}

}  // namespace

Setup readSetup(const ConfigText& text, const std::vector<Override>& overrides) {
  SectionReader r(text, sectionSpec("Setup"), overrides);
  Setup s;
  s.file = text.name;
  s.load = r.boolean("Load", false);
  s.save = r.boolean("Save", false);
  s.loadFile = r.path("LoadFile");
  s.saveFile = r.path("SaveFile");
  s.hairstyleInfo = r.path("HairstyleInfo");
  s.collisionInfo = r.path("CollisionInfo");
  s.visualityInfo = r.path("VisualityInfo");
  s.renderInfo = r.path("RenderInfo");
  s.wickModel = r.path("WickModel");
  s.headModel = r.path("HeadModel");
  s.hairVert = r.path("HairVert");
  s.hairFrag = r.path("HairFrag");
  s.headVert = r.path("HeadVert");
  s.headFrag = r.path("HeadFrag");
  if (s.load && !s.loadFile.given())
    throw InputError(r.where("Load"),
                     "Load is true but no LoadFile names the coupe to load; add `LoadFile PATH`");
  if (s.save && !s.saveFile.given())
    throw InputError(r.where("Save"),
                     "Save is true but no SaveFile names where to save; add `SaveFile PATH`");
  r.finish();
  return s;
}

Hairstyle readHairstyle(const ConfigText& text, const std::vector<Override>& overrides) {
  SectionReader r(text, sectionSpec("Hairstyle"), overrides);
  Hairstyle h;
  h.visualityStep = r.real("VisualityStep", h.visualityStep, {0.0, 1.0, true, false});
  h.collisionStep = r.real("CollisionStep", h.collisionStep, {0.0, 1.0, true, false});
  h.maxIter = static_cast<int>(r.integer("MaxIter", h.maxIter, 1, 1000000));
  h.epsilon = r.real("Epsilon", h.epsilon, Range::positive());
  h.hairLengths = r.realList("HairLengths", {0.0, 10.0, true, false});
  if (h.hairLengths.size() > 256)
    throw InputError(r.where("HairLengths"), "at most 256 Super-Helix elements are supported, found " +
                                                 std::to_string(h.hairLengths.size()));
  h.hairDensity = r.real("HairDensity", h.hairDensity, Range::nonNegative());
  h.hairRadius1 = r.real("HairRadius1", h.hairRadius1, {0.0, 0.01, true, false});
  h.hairRadius2 = r.real("HairRadius2", h.hairRadius2, {0.0, 0.01, true, false});
  h.helixRadius = r.real("HelixRadius", h.helixRadius, Range::closed(0.0, 1000.0));
  h.helixStep = r.real("HelixStep", h.helixStep, Range::closed(-1000.0, 1000.0));
  h.poisson = r.real("Poisson", h.poisson, {-1.0, 0.5, true, false});
  h.young = r.real("Young", h.young, Range::positive());
  h.density = r.real("Density", h.density, Range::nonNegative());
  h.gravity = r.real("Gravity", h.gravity, Range::closed(0.0, 1000.0));
  h.model = r.word("Model", "superhelix", {"superhelix", "cantilever"}) == "cantilever"
                ? StylingModel::kCantilever
                : StylingModel::kSuperHelix;
  h.clump = r.real("Clump", h.clump, Range::closed(0.0, 1.0));
  h.strayHairs = r.boolean("StrayHairs", h.strayHairs);
  h.seed = r.unsignedInteger("Seed", h.seed);
  h.segments = static_cast<int>(r.integer("Segments", h.segments, 1, 100000));
  h.flexuralRigidity = r.real("FlexuralRigidity", h.flexuralRigidity, Range::nonNegative());
  if (r.has("JointAngleLimit")) {
    std::vector<const ConfigLine*> limit = r.lines("JointAngleLimit");
    const ConfigLine& line = *limit.front();
    if (line.values.empty() || line.values.size() > 2)
      throw r.error(line, "JointAngleLimit takes degrees and, optionally, the first node it applies to");
    h.jointLimit = r.checkReal(line, 0, Range::closed(0.0, 180.0), "degrees");
    if (line.values.size() == 2) {
      double from = r.checkReal(line, 1, Range::closed(1.0, 100000.0), "first node");
      if (from != std::floor(from)) throw r.error(line, "the first node must be a whole number");
      h.jointLimitFrom = static_cast<int>(from);
    }
  }
  for (const ConfigLine* line : r.lines("Force")) h.forces.push_back(readForce(r, *line));
  for (const ConfigLine* line : r.lines("Cut")) {
    if (line->values.size() != 4)
      throw r.error(*line, "Cut takes azimuthFrom azimuthTo zenithMax height, found " +
                               std::to_string(line->values.size()) + " values");
    HairCut c;
    c.azimuthFrom = r.checkReal(*line, 0, Range::closed(-360.0, 360.0), "azimuth");
    c.azimuthTo = r.checkReal(*line, 1, Range::closed(-360.0, 360.0), "azimuth");
    c.zenithMax = r.checkReal(*line, 2, Range::closed(0.0, 180.0), "zenith");
    c.height = r.checkReal(*line, 3, {}, "height");
    c.where = line->where;
    h.cuts.push_back(c);
  }
  r.finish();
  return h;
}

Collision readCollision(const ConfigText& text, const std::vector<Override>& overrides) {
  SectionReader r(text, sectionSpec("Collision"), overrides);
  // Shapes keep their file order whatever their kind: the order is part of the output's identity.
  std::vector<std::pair<const ConfigLine*, ShapeKind>> all;
  for (const ConfigLine* line : r.lines("Sphere")) all.emplace_back(line, ShapeKind::kSphere);
  for (const ConfigLine* line : r.lines("Ellipsoid")) all.emplace_back(line, ShapeKind::kEllipsoid);
  for (const ConfigLine* line : r.lines("Cuboid")) all.emplace_back(line, ShapeKind::kCuboid);
  std::stable_sort(all.begin(), all.end(), [](const auto& a, const auto& b) {
    if (a.first->where.file != b.first->where.file)
      return a.first->where.line > 0 && b.first->where.line == 0;
    return a.first->where.line < b.first->where.line;
  });
  Collision c;
  for (const auto& [line, kind] : all) c.shapes.push_back(readShape(r, *line, kind));
  r.finish();
  return c;
}

Visuality readVisuality(const ConfigText& text, const std::vector<Override>& overrides) {
  SectionReader r(text, sectionSpec("Visuality"), overrides);
  Visuality v;
  v.ambientColor = r.vec3("AmbientColor", v.ambientColor, Range::closed(0.0, 1000.0));
  v.diffuseColor = r.vec3("DiffuseColor", v.diffuseColor, Range::closed(0.0, 1000.0));
  v.specularColor = r.vec3("SpecularColor", v.specularColor, Range::closed(0.0, 1000.0));
  v.glossiness = r.real("Glossiness", v.glossiness, Range::closed(0.0, 100000.0));
  v.ambientMean = r.real("AmbientMean", v.ambientMean, Range::closed(0.0, 1000.0));
  v.ambientDeviation = r.real("AmbientDeviation", v.ambientDeviation, Range::closed(0.0, 1000.0));
  r.finish();
  return v;
}

RenderSettings readRender(const ConfigText& text, const std::vector<Override>& overrides) {
  SectionReader r(text, sectionSpec("Render"), overrides);
  RenderSettings s;
  std::vector<double> res =
      r.reals("Resolution", 2, std::vector<double>{double(s.resolution.x), double(s.resolution.y)},
              Range::closed(1, 16384));
  if (res[0] != std::floor(res[0]) || res[1] != std::floor(res[1]))
    throw InputError(r.where("Resolution"), "Resolution must be two whole numbers of pixels");
  s.resolution = glm::ivec2(static_cast<int>(res[0]), static_cast<int>(res[1]));
  s.cameraPosition = r.vec3("CameraPosition", s.cameraPosition);
  s.cameraTarget = r.vec3("CameraTarget", s.cameraTarget);
  s.cameraUp = r.vec3("CameraUp", s.cameraUp);
  if (glm::length(s.cameraTarget - s.cameraPosition) < 1e-9)
    throw InputError(r.where("CameraTarget"),
                     "CameraTarget equals CameraPosition; the camera needs a direction");
  if (glm::length(glm::cross(s.cameraUp, s.cameraTarget - s.cameraPosition)) < 1e-9)
    throw InputError(r.where("CameraUp"), "CameraUp is zero or parallel to the view direction");
  s.fieldOfView = r.real("FieldOfView", s.fieldOfView, {0.0, 180.0, true, true});
  s.lightPosition = r.vec3("LightPosition", s.lightPosition);
  s.lightColor = r.vec3("LightColor", s.lightColor, Range::closed(0.0, 1e6));
  s.ambientIntensity = r.real("AmbientIntensity", s.ambientIntensity, Range::closed(0.0, 1e6));
  s.samples = static_cast<int>(r.integer("Samples", s.samples, 1, 64));
  std::vector<double> layers = r.reals(
      "LayerSizes", 4, std::vector<double>{s.layerSizes.x, s.layerSizes.y, s.layerSizes.z, s.layerSizes.w},
      Range::positive());
  s.layerSizes = glm::dvec4(layers[0], layers[1], layers[2], layers[3]);
  s.strandOpacity = r.real("StrandOpacity", s.strandOpacity, Range::closed(0.0, 1.0));
  s.strandWidth = r.real("StrandWidth", s.strandWidth, {0.0, 1.0, true, false});
  std::string model = r.word("ShadingModel", "kajiya-kay", {"kajiya-kay", "thesis", "anjyo", "volumetric"});
  s.shadingModel = model == "thesis"       ? ShadingModel::kThesis
                   : model == "anjyo"      ? ShadingModel::kAnjyo
                   : model == "volumetric" ? ShadingModel::kVolumetric
                                           : ShadingModel::kKajiyaKay;
  s.background = r.vec3("Background", s.background, Range::closed(0.0, 1e6));
  s.headColor = r.vec3("HeadColor", s.headColor, Range::closed(0.0, 1.0));
  s.voxelSize = r.real("VoxelSize", s.voxelSize, {0.0, 1000.0, true, false});  // large for caches in cm or mm
  s.volumePadding = static_cast<int>(r.integer("VolumePadding", s.volumePadding, 1, 64));
  s.shellDensity = r.real("ShellDensity", s.shellDensity, {0.0, 100.0, true, false});
  s.volumetricBlend = r.real("VolumetricBlend", s.volumetricBlend, Range::closed(0.0, 1.0));
  r.finish();
  return s;
}

Config loadConfig(const std::filesystem::path& setupFile, const std::vector<Override>& overrides,
                  SetupUse use) {
  Config config;
  config.overrides = overrides;
  config.setup = readSetup(readConfigText(setupFile), overrides);
  const Setup& s = config.setup;
  bool grows = use == SetupUse::kGrow || use == SetupUse::kInterpolate || (use == SetupUse::kRun && !s.load);

  auto need = [&](const PathRef& ref, const char* key, const char* why) {
    if (!ref.given())
      throw InputError({setupFile.string(), 0},
                       std::string("missing required key '") + key + "' (" + why + ")");
  };
  if (grows) {
    need(s.hairstyleInfo, "HairstyleInfo", "path of the Hairstyle Info file");
    need(s.wickModel, "WickModel", "path of the wick OBJ");
  }
  for (auto [ref, key] : {std::pair{&s.hairstyleInfo, "HairstyleInfo"},
                          {&s.collisionInfo, "CollisionInfo"},
                          {&s.visualityInfo, "VisualityInfo"},
                          {&s.renderInfo, "RenderInfo"},
                          {&s.wickModel, "WickModel"},
                          {&s.headModel, "HeadModel"},
                          {&s.hairVert, "HairVert"},
                          {&s.hairFrag, "HairFrag"},
                          {&s.headVert, "HeadVert"},
                          {&s.headFrag, "HeadFrag"}})
    if (ref->given()) requireExisting(*ref, key);
  if (s.load && (use == SetupUse::kRun || use == SetupUse::kCheck)) requireExisting(s.loadFile, "LoadFile");

  auto text = [&](const PathRef& ref, const char* what) {
    return ref.given() ? readConfigText(ref.path) : emptyText(setupFile, what);
  };
  if (s.hairstyleInfo.given() || grows)
    config.hairstyle = readHairstyle(text(s.hairstyleInfo, "Hairstyle Info"), overrides);
  config.collision = readCollision(text(s.collisionInfo, "Collision Info"), overrides);
  config.visuality = readVisuality(text(s.visualityInfo, "Visuality Info"), overrides);
  config.render = readRender(text(s.renderInfo, "Render Info"), overrides);
  return config;
}

}  // namespace hairgen
