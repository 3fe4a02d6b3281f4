// Every config key hairgen reads, declared once (DESIGN §4): the sections Setup, Hairstyle Info,
// Collision Info, Visuality Info and Render Info. The reader, the canonical text behind the config
// digest, --set and `hairgen check --keys` all come from these tables; a new key is one line here and
// the code that uses its value.
#include "libcore/config/keys.h"

#include <algorithm>
#include <cmath>
#include <iterator>

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

// The values after the kind: volume penalty centre, then the radius or the half-extents and axes.
std::string shapeText(const CollisionShape& c) {
  if (c.fitted) return join({c.envelopeGrowth, c.penalty}) + " auto";
  std::string out = join({c.envelopeGrowth, c.penalty}) + " " + join(c.centre) + " " + join(c.halfExtents);
  if (c.kind != ShapeKind::kSphere)
    out += " " + join(c.axes[0]) + " " + join(c.axes[1]) + " " + join(c.axes[2]);
  return out;
}

CollisionShape readShape(const SectionReader& reader, const ConfigLine& line, ShapeKind kind) {
  if (line.values.size() == 3 && toLower(line.values[2]) == "auto") {
    CollisionShape shape;
    shape.kind = kind;
    shape.where = line.where;
    shape.fitted = true;
    shape.envelopeGrowth = reader.checkReal(line, 0, {}, "volume");
    shape.penalty = reader.checkReal(line, 1, Range::nonNegative(), "penalty");
    return shape;
  }
  size_t count = kind == ShapeKind::kSphere ? 6 : 17;
  if (line.values.size() != count)
    throw reader.error(
        line, "'" + line.key + "' takes " + std::to_string(count) + " values, found " +
                  std::to_string(line.values.size()) + "; expected " +
                  (kind == ShapeKind::kSphere ? "volume penalty cx cy cz r"
                                              : "volume penalty cx cy cz a b c ux uy uz vx vy vz wx wy wz") +
                  (kind == ShapeKind::kCuboid ? "" : ", or volume penalty auto (fitted to the head)"));
  CollisionShape shape;
  shape.kind = kind;
  shape.where = line.where;
  shape.envelopeGrowth = reader.checkReal(line, 0, {}, "volume");
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

// ---------------------------------------------------------------------------------------------- Setup

// MeshUnits and MeshUpAxis enter the digest only when given, so that the digest of a Setup written
// before they existed does not change.
Key<Setup> meshUnitsKey() {
  return customKey<Setup>(
      {"MeshUnits", "", "the length unit of the wick and head OBJs: m, cm, mm, in, or metres per unit"},
      "m | cm | mm | in | factor", "[1e-06, 1000] metres per unit",
      [](SectionReader& r, Setup& s) {
        const ConfigLine* line = r.line("MeshUnits");
        if (!line) return;
        std::optional<double> unit =
            line->values.size() == 1 ? parseLengthUnit(line->values[0]) : std::nullopt;
        if (!unit)
          throw r.error(*line, "MeshUnits takes m, cm, mm, in or a number of metres per unit from " +
                                   formatReal(kMinMetresPerUnit) + " m (a micrometre) to " +
                                   formatReal(kMaxMetresPerUnit) + " m (a kilometre)");
        s.meshConversion.metresPerUnit = unit;
      },
      [](const Setup& s) {
        return s.meshConversion.metresPerUnit && *s.meshConversion.metresPerUnit != 1.0
                   ? std::vector<std::string>{formatReal(*s.meshConversion.metresPerUnit)}
                   : std::vector<std::string>{};
      });
}

Key<Setup> meshUpAxisKey() {
  return customKey<Setup>(
      {"MeshUpAxis", "", "the up axis of the wick and head OBJs: z turns z-up to hairgen's +y up"}, "y | z",
      "",
      [](SectionReader& r, Setup& s) {
        const ConfigLine* line = r.line("MeshUpAxis");
        if (!line) return;
        std::optional<UpAxis> axis = line->values.size() == 1 ? parseUpAxis(line->values[0]) : std::nullopt;
        if (!axis) throw r.error(*line, "MeshUpAxis takes y or z");
        s.meshConversion.upAxis = axis;
      },
      [](const Setup& s) {
        return s.meshConversion.upAxis == UpAxis::kZ ? std::vector<std::string>{"z"}
                                                     : std::vector<std::string>{};
      });
}

// HeadModel none (any case) or "" is no head, as when the Setup names none.
Key<Setup> headModelKey() {
  Key<Setup> key = pathKey<Setup>(
      {"HeadModel", "", "the head OBJ: rendered, and shadows the hair; none (or \"\") for no head"},
      &Setup::headModel);
  key.spec.value = "path | none";
  key.read = [path = key.read](SectionReader& r, Setup& s) {
    const ConfigLine* line = r.line("HeadModel");
    if (line && line->values.size() == 1 && toLower(line->values[0]) == "none") return;
    path(r, s);
  };
  return key;
}

Section<Setup> makeSetup() {
  auto notInDigest = [](Key<Setup> key) {
    key.spec.inDigest = false;
    return key;
  };
  return makeSection<Setup>(
      "Setup", "Setup", "",
      {notInDigest(
           boolKey<Setup>({"Load", "", "read the coupe from LoadFile instead of growing it"}, &Setup::load)),
       notInDigest(boolKey<Setup>({"Save", "", "write the coupe to SaveFile"}, &Setup::save)),
       pathKey<Setup>({"LoadFile", "", "the coupe to load (.hair, .gltf, .glb)", {"LoadPath"}},
                      &Setup::loadFile),
       pathKey<Setup>({"SaveFile", "", "where to save the coupe (.hair, .gltf, .glb)", {"SavePath"}},
                      &Setup::saveFile),
       pathKey<Setup>({"HairstyleInfo", "", "the Hairstyle Info file"}, &Setup::hairstyleInfo),
       pathKey<Setup>({"CollisionInfo", "", "the Collision Info file"}, &Setup::collisionInfo),
       pathKey<Setup>({"VisualityInfo", "", "the Visuality Info file"}, &Setup::visualityInfo),
       pathKey<Setup>({"RenderInfo", "", "the Render Info file"}, &Setup::renderInfo),
       pathKey<Setup>({"DynamicsInfo", "", "the Dynamics Info file: naming one makes the hair move"},
                      &Setup::dynamicsInfo),
       pathKey<Setup>({"WickModel", "", "the wick OBJ: every vertex a follicle", {"HairModel"}},
                      &Setup::wickModel),
       headModelKey(),
       pathKey<Setup>({"HairVert", "",
                       "GLSL hair vertex stage of every pass, in place of hairgen's (docs/rendering.md, "
                       "Custom shaders)"},
                      &Setup::hairVert),
       pathKey<Setup>({"HairFrag", "",
                       "GLSL fragment stage shading the hair, in place of hairgen's (docs/rendering.md, "
                       "Custom shaders)"},
                      &Setup::hairFrag),
       pathKey<Setup>({"HeadVert", "",
                       "GLSL head vertex stage of every pass, in place of hairgen's (docs/rendering.md, "
                       "Custom shaders)"},
                      &Setup::headVert),
       pathKey<Setup>({"HeadFrag", "",
                       "GLSL fragment stage shading the head, in place of hairgen's (docs/rendering.md, "
                       "Custom shaders)"},
                      &Setup::headFrag),
       meshUnitsKey(), meshUpAxisKey(),
       customKey<Setup>(
           {"WickGroup", "",
            "grow only on the faces of this OBJ group, object or material of the wick (a whole head can be "
            "the wick)"},
           "name", "",
           [](SectionReader& r, Setup& s) {
             const ConfigLine* line = r.line("WickGroup");
             if (!line) return;
             if (line->values.size() != 1) throw r.error(*line, "WickGroup takes one name");
             s.wickGroup = line->values[0];
           },
           [](const Setup& s) {
             return s.wickGroup.empty() ? std::vector<std::string>{} : std::vector<std::string>{s.wickGroup};
           })},
      [](SectionReader& r, Setup& s) {
        if (s.load && !s.loadFile.given())
          throw InputError(r.where("Load"),
                           "Load is true but no LoadFile names the coupe to load; add `LoadFile PATH`");
        if (s.save && !s.saveFile.given())
          throw InputError(r.where("Save"),
                           "Save is true but no SaveFile names where to save; add `SaveFile PATH`");
        s.file = r.fileName();
      });
}

// ------------------------------------------------------------------------------------------ Hairstyle

Key<Hairstyle> hairLengthsKey() {
  return required(customKey<Hairstyle>(
      {"HairLengths",
       "m",
       "one length per Super-Helix element (at most 256), e.g. 0.04 0.04 0.04 0.04",
       {"HairLength"}},
      "real ...", "(0, 10]",
      [](SectionReader& r, Hairstyle& h) {
        h.hairLengths = r.realList("HairLengths", {0.0, 10.0, true, false});
        if (h.hairLengths.size() > 256)
          throw InputError(r.where("HairLengths"), "at most 256 Super-Helix elements are supported, found " +
                                                       std::to_string(h.hairLengths.size()));
      },
      [](const Hairstyle& h) {
        std::string out;
        for (double l : h.hairLengths) out += (out.empty() ? "" : " ") + formatReal(l);
        return std::vector<std::string>{out};
      }));
}

Key<Hairstyle> jointLimitKey() {
  return customKey<Hairstyle>(
      {"JointAngleLimit", "degrees",
       "cantilever: the largest turn between consecutive segments, from node n on (180 = none)"},
      "degrees [n]", "[0, 180], n >= 1",
      [](SectionReader& r, Hairstyle& h) {
        if (!r.has("JointAngleLimit")) return;
        const ConfigLine& line = *r.line("JointAngleLimit");
        if (line.values.size() > 2)
          throw r.error(line, "JointAngleLimit takes degrees and, optionally, the first node it applies to");
        h.jointLimit = r.checkReal(line, 0, Range::closed(0.0, 180.0), "degrees");
        if (line.values.size() == 2) {
          double from = r.checkReal(line, 1, Range::closed(1.0, 100000.0), "first node");
          if (from != std::floor(from)) throw r.error(line, "the first node must be a whole number");
          h.jointLimitFrom = static_cast<int>(from);
        }
      },
      [](const Hairstyle& h) {
        return std::vector<std::string>{formatReal(h.jointLimit) + " " + std::to_string(h.jointLimitFrom)};
      });
}

Key<Hairstyle> forceKey() {
  return repeatable(customKey<Hairstyle>(
      {"Force", "m/s²", "cantilever: an acceleration added to gravity on the segments starting in a region"},
      "ax ay az all | above Y | below Y | side +x|-x|+z|-z | box x0 y0 z0 x1 y1 z1", "",
      [](SectionReader& r, Hairstyle& h) {
        for (const ConfigLine* line : r.lines("Force")) h.forces.push_back(readForce(r, *line));
      },
      [](const Hairstyle& h) {
        std::vector<std::string> lines;
        for (const ForceField& f : h.forces)
          lines.push_back(join(f.acceleration) + " " + std::to_string(int(f.region)) + " " +
                          formatReal(f.level) + " " + join(f.side) + " " + join(f.lo) + " " + join(f.hi));
        return lines;
      }));
}

Key<Hairstyle> cutKey() {
  return repeatable(customKey<Hairstyle>(
      {"Cut", "degrees, m",
       "cantilever: pores with azimuth in [from, to] (from the face toward +x) and zenith <= max end at "
       "their last node above the height"},
      "azimuthFrom azimuthTo zenithMax height", "",
      [](SectionReader& r, Hairstyle& h) {
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
      },
      [](const Hairstyle& h) {
        std::vector<std::string> lines;
        for (const HairCut& c : h.cuts)
          lines.push_back(join({c.azimuthFrom, c.azimuthTo, c.zenithMax, c.height}));
        return lines;
      }));
}

// RootTilt and RootFlow enter the digest only when they lean the hair, so that the digest of a
// Hairstyle Info written before them does not change.
Key<Hairstyle> rootTiltKey() {
  return customKey<Hairstyle>(
      {"RootTilt", "degrees", "each hair leaves the scalp this far from the normal, toward RootFlow"},
      "degrees", "[0, 89]",
      [](SectionReader& r, Hairstyle& h) { h.rootTilt = r.real("RootTilt", 0.0, Range::closed(0.0, 89.0)); },
      [](const Hairstyle& h) {
        return h.rootTilt > 0.0 ? std::vector<std::string>{formatReal(h.rootTilt)}
                                : std::vector<std::string>{};
      });
}

Key<Hairstyle> rootFlowKey() {
  return customKey<Hairstyle>(
      {"RootFlow", "m",
       "the direction follicles lean toward: down, a vector x y z, away-from x y z (a point, e.g. the "
       "whorl), or away-from auto (the whorl of the head read, docs/real-heads.md)"},
      "down | x y z | away-from x y z | away-from auto", "",
      [](SectionReader& r, Hairstyle& h) {
        const ConfigLine* line = r.line("RootFlow");
        if (!line) return;
        const std::vector<std::string>& v = line->values;
        const std::string first = toLower(v[0]);
        if (first == "down" && v.size() == 1) return;
        const bool away = first == "away-from";
        if (away && v.size() == 2 && toLower(v[1]) == "auto") {
          h.rootFlow.kind = RootFlow::Kind::kAwayFrom;
          h.rootFlow.fitted = true;
          return;
        }
        if (v.size() != (away ? 4u : 3u))
          throw r.error(*line, "RootFlow takes down, a direction x y z, away-from x y z or away-from auto");
        glm::dvec3 value;
        for (int i = 0; i < 3; ++i)
          value[i] = r.checkReal(*line, away + i, Range::closed(-1e4, 1e4), "RootFlow");
        if (!away && glm::length(value) < 1e-9) throw r.error(*line, "RootFlow's direction is zero");
        h.rootFlow.kind = away ? RootFlow::Kind::kAwayFrom : RootFlow::Kind::kDirection;
        h.rootFlow.value = away ? value : glm::normalize(value);
      },
      [](const Hairstyle& h) {
        if (h.rootTilt <= 0.0 || h.rootFlow.kind == RootFlow::Kind::kDown) return std::vector<std::string>{};
        if (h.rootFlow.fitted)
          return std::vector<std::string>{"away-from auto"};  // the head's digest decides
        return std::vector<std::string>{
            std::string(h.rootFlow.kind == RootFlow::Kind::kAwayFrom ? "away-from " : "") +
            join(h.rootFlow.value)};
      });
}

Section<Hairstyle> makeHairstyle() {
  using H = Hairstyle;
  const Range aboveZeroToOne{0.0, 1.0, true, false};
  return makeSection<H>(
      "Hairstyle", "Hairstyle Info", "HairstyleInfo",
      {realKey<H>({"VisualityStep", "m", "arc length between output vertices"}, &H::visualityStep,
                  aboveZeroToOne),
       realKey<H>({"CollisionStep", "m", "arc length between collision samples"}, &H::collisionStep,
                  aboveZeroToOne),
       choiceKey<H, Minimiser>({"Minimiser", "",
                                "rosenbrock (the thesis' direct search) or bfgs (quasi-Newton on the "
                                "energy's analytic gradient)"},
                               &H::minimiser, {Minimiser::kRosenbrock, Minimiser::kBfgs}),
       integerKey<H>({"MaxIter", "", "Rosenbrock stages at most; bfgs: iterations at most, per coordinate"},
                     &H::maxIter, 1, 1000000),
       realKey<H>({"Epsilon", "",
                   "relative energy change between stages that ends minimisation (bfgs: the predicted and "
                   "the last decrease both below Epsilon/100)"},
                  &H::epsilon, Range::positive()),
       hairLengthsKey(),
       realKey<H>({"HairDensity", "strands/cm²", "strands per square centimetre of wick"}, &H::hairDensity,
                  Range::nonNegative()),
       realKey<H>({"HairRadius1", "m", "semi-axis a of the elliptic cross-section"}, &H::hairRadius1,
                  {0.0, 0.01, true, false}),
       realKey<H>({"HairRadius2", "m", "semi-axis b of the elliptic cross-section"}, &H::hairRadius2,
                  {0.0, 0.01, true, false}),
       realKey<H>({"HelixRadius", "m", "radius of the rest helix; 0 = straight"}, &H::helixRadius,
                  Range::closed(0.0, 1000.0)),
       realKey<H>({"HelixStep", "m", "rise per turn of the rest helix"}, &H::helixStep,
                  Range::closed(-1000.0, 1000.0)),
       realKey<H>({"Poisson", "", "Poisson's ratio σ"}, &H::poisson, {-1.0, 0.5, true, false}),
       realKey<H>({"Young", "Pa", "Young's modulus E"}, &H::young, Range::positive()),
       realKey<H>({"Density", "kg/m³", "mass density ρ of the hair fibre"}, &H::massDensity,
                  Range::nonNegative()),
       realKey<H>({"Gravity", "N/kg", "gravitational acceleration g, pulling along -y"}, &H::gravity,
                  Range::closed(0.0, 1000.0)),
       choiceKey<H, StylingModel>(
           {"Model", "", "the styling model: Super-Helix guides or Anjyo's cantilever"}, &H::model,
           {StylingModel::kSuperHelix, StylingModel::kCantilever}),
       realKey<H>({"Clump", "", "tip weights drawn in [0, Clump): 0 gathers tips at the nearest guide"},
                  &H::clump, Range::closed(0.0, 1.0)),
       boolKey<H>({"StrayHairs", "", "true = the thesis' barycentric assignment (§4.1.4.4)"}, &H::strayHairs),
       unsignedKey<H>({"Seed", "", "keys every random number; --seed overrides it"}, &H::seed),
       rootTiltKey(),
       rootFlowKey(),
       integerKey<H>({"Segments", "", "cantilever: equal segments per hair"}, &H::segments, 1, 100000),
       realKey<H>({"FlexuralRigidity", "N·m²", "cantilever: E·I; 0 = Young × π a b³/4"}, &H::flexuralRigidity,
                  Range::nonNegative()),
       jointLimitKey(),
       forceKey(),
       cutKey()});
}

// ------------------------------------------------------------------------------------------ Collision

Key<Collision> shapeKey(const char* name, ShapeKind kind, std::vector<std::string> aliases) {
  return repeatable(customKey<Collision>(
      {name, "m",
       kind == ShapeKind::kSphere
           ? "a sphere: envelope growth, penalty k >= 0, centre, radius > 0"
           : std::string(kind == ShapeKind::kEllipsoid ? "an ellipsoid" : "a box") +
                 ": envelope growth, penalty k >= 0, centre, half-extents > 0 along three axes",
       std::move(aliases)},
      kind == ShapeKind::kSphere ? "volume penalty cx cy cz r"
                                 : "volume penalty cx cy cz a b c ux uy uz vx vy vz wx wy wz",
      "",
      [name, kind](SectionReader& r, Collision& c) {
        for (const ConfigLine* line : r.lines(name)) c.shapes.push_back(readShape(r, *line, kind));
      },
      [kind](const Collision& c) {
        std::vector<std::string> lines;
        for (const CollisionShape& s : c.shapes)
          if (s.kind == kind) lines.push_back(shapeText(s));
        return lines;
      }));
}

Section<Collision> makeCollision() {
  return makeSection<Collision>(
      "Collision", "Collision Info", "CollisionInfo",
      {shapeKey("Sphere", ShapeKind::kSphere, {}), shapeKey("Ellipsoid", ShapeKind::kEllipsoid, {"Elipsoid"}),
       shapeKey("Cuboid", ShapeKind::kCuboid, {})},
      [](SectionReader&, Collision& c) {
        // The shapes keep their file order whatever their kind (it is part of the output's identity):
        // the file's lines in order, then those of --set.
        std::stable_sort(c.shapes.begin(), c.shapes.end(),
                         [](const CollisionShape& a, const CollisionShape& b) {
                           if (a.where.file != b.where.file) return a.where.line > 0 && b.where.line == 0;
                           return a.where.line < b.where.line;
                         });
      },
      [](const Collision& c) {
        std::vector<std::string> lines;
        for (const CollisionShape& s : c.shapes)
          lines.push_back(std::string(name(s.kind)) + " " + shapeText(s));
        return lines;
      });
}

// ------------------------------------------------------------------------------------------ Visuality

Section<Visuality> makeVisuality() {
  using V = Visuality;
  const Range colorRange = Range::closed(0.0, 1000.0);
  return makeSection<V>(
      "Visuality", "Visuality Info", "VisualityInfo",
      {vectorKey<V, 3>({"AmbientColor", "", "ambient reflectance of the hair"}, &V::ambientColor, "r g b",
                       colorRange),
       vectorKey<V, 3>({"DiffuseColor", "", "diffuse reflectance of the hair"}, &V::diffuseColor, "r g b",
                       colorRange),
       vectorKey<V, 3>({"SpecularColor", "", "specular reflectance of the hair"}, &V::specularColor, "r g b",
                       colorRange),
       realKey<V>({"Glossiness", "", "specular exponent p"}, &V::glossiness, Range::closed(0.0, 100000.0)),
       realKey<V>({"AmbientMean", "", "hairgen shade: mean of the per-strand ambient coefficient (Anjyo)"},
                  &V::ambientMean, colorRange),
       realKey<V>({"AmbientDeviation", "", "hairgen shade: its standard deviation"}, &V::ambientDeviation,
                  colorRange)});
}

// --------------------------------------------------------------------------------------------- Render

Key<RenderSettings> resolutionKey() {
  return customKey<RenderSettings>(
      {"Resolution", "pixels", "width and height of the image"}, "width height", "[1, 16384]",
      [](SectionReader& r, RenderSettings& s) {
        std::vector<double> res =
            r.reals("Resolution", 2, std::vector<double>{double(s.resolution.x), double(s.resolution.y)},
                    Range::closed(1, 16384));
        if (res[0] != std::floor(res[0]) || res[1] != std::floor(res[1]))
          throw InputError(r.where("Resolution"), "Resolution must be two whole numbers of pixels");
        s.resolution = glm::ivec2(static_cast<int>(res[0]), static_cast<int>(res[1]));
      },
      [](const RenderSettings& s) {
        return std::vector<std::string>{std::to_string(s.resolution.x) + " " +
                                        std::to_string(s.resolution.y)};
      });
}

Section<RenderSettings> makeRender() {
  using R = RenderSettings;
  const Range colorRange = Range::closed(0.0, 1e6);
  return makeSection<R>(
      "Render", "Render Info", "RenderInfo",
      {resolutionKey(),
       customKey<R>(
           {"CameraPosition", "m",
            "where the camera is; auto frames the hair and the head from a three-quarter view, the light "
            "placed relative to it"},
           "auto | x y z", "",
           [](SectionReader& r, R& s) {
             const ConfigLine* line = r.line("CameraPosition");
             if (!line || (line->values.size() == 1 && toLower(line->values[0]) == "auto")) return;
             if (line->values.size() != 3) throw r.error(*line, "CameraPosition takes auto or x y z");
             s.cameraAuto = false;
             for (int i = 0; i < 3; ++i) s.cameraPosition[i] = r.checkReal(*line, i, {}, "position");
           },
           [](const R& s) {
             return std::vector<std::string>{s.cameraAuto ? std::string("auto") : join(s.cameraPosition)};
           }),
       vectorKey<R, 3>({"CameraTarget", "m", "the point the camera looks at"}, &R::cameraTarget, "x y z"),
       vectorKey<R, 3>({"CameraUp", "", "the camera's up direction"}, &R::cameraUp, "x y z"),
       realKey<R>({"FieldOfView", "degrees", "vertical field of view"}, &R::fieldOfView,
                  {0.0, 180.0, true, true}),
       vectorKey<R, 3>({"LightPosition", "m", "the point light"}, &R::lightPosition, "x y z"),
       vectorKey<R, 3>({"LightColor", "", "the light's colour and intensity"}, &R::lightColor, "r g b",
                       colorRange),
       realKey<R>({"AmbientIntensity", "", "ambient light"}, &R::ambientIntensity, colorRange),
       integerKey<R>({"Samples", "", "antialiasing samples per pixel (k² for k×k sub-pixels)"}, &R::samples,
                     1, 64),
       vectorKey<R, 4>({"LayerSizes", "m", "the depths of the four deep-opacity layers"}, &R::layerSizes,
                       "d1 d2 d3 d4", Range::positive()),
       realKey<R>({"StrandOpacity", "", "opacity of one strand"}, &R::strandOpacity, Range::closed(0.0, 1.0)),
       realKey<R>({"StrandWidth", "m", "on-screen diameter of a strand"}, &R::strandWidth,
                  {0.0, 1.0, true, false}),
       choiceKey<R, ShadingModel>({"ShadingModel", "", "how strands are lit (docs/rendering.md)"},
                                  &R::shadingModel, {std::begin(kShadingModels), std::end(kShadingModels)}),
       vectorKey<R, 3>({"Background", "", "the preview's background colour"}, &R::background, "r g b",
                       colorRange),
       vectorKey<R, 3>({"HeadColor", "", "Lambert albedo of the head"}, &R::headColor, "r g b",
                       Range::closed(0.0, 1.0)),
       realKey<R>(
           {"VoxelSize", "m", "hairgen shade: spacing of the density grid (large for caches in cm or mm)"},
           &R::voxelSize, {0.0, 1000.0, true, false}),
       integerKey<R>({"VolumePadding", "voxels", "hairgen shade: empty voxels around the hair"},
                     &R::volumePadding, 1, 64),
       realKey<R>(
           {"ShellDensity", "", "hairgen shade: the shell's density as a fraction of a typical hair point's"},
           &R::shellDensity, {0.0, 100.0, true, false}),
       realKey<R>({"VolumetricBlend", "", "0 = Kajiya-Kay, 1 = volumetric"}, &R::volumetricBlend,
                  Range::closed(0.0, 1.0))},
      [](SectionReader& r, R& s) {
        if (s.cameraAuto) return;  // the stage aims it
        if (glm::length(s.cameraTarget - s.cameraPosition) < 1e-9)
          throw InputError(r.where("CameraTarget"),
                           "CameraTarget equals CameraPosition; the camera needs a direction");
        if (glm::length(glm::cross(s.cameraUp, s.cameraTarget - s.cameraPosition)) < 1e-9)
          throw InputError(r.where("CameraUp"), "CameraUp is zero or parallel to the view direction");
      });
}

// ------------------------------------------------------------------------------------------ Dynamics

// A whole frame number (a key may name any frame, before or after the shot).
double frameOf(const SectionReader& r, const ConfigLine& line) {
  double frame = r.checkReal(line, 0, Range::closed(-1e6, 1e6), "frame");
  if (frame != std::floor(frame)) throw r.error(line, "the frame must be a whole number");
  return frame;
}

Key<Dynamics> framesKey() {
  return customKey<Dynamics>(
      {"Frames", "", "the first frame (the rest state, the input guides) and the last"}, "first last",
      "whole numbers, first < last",
      [](SectionReader& r, Dynamics& d) {
        const ConfigLine* line = r.line("Frames");
        if (!line) return;
        if (line->values.size() != 2) throw r.error(*line, "Frames takes the first and the last frame");
        const double first = frameOf(r, *line),
                     last = r.checkReal(*line, 1, Range::closed(-1e6, 1e6), "last");
        if (last != std::floor(last) || !(last > first))
          throw r.error(*line, "the last frame must be a whole number after the first");
        d.firstFrame = int(first);
        d.lastFrame = int(last);
      },
      [](const Dynamics& d) {
        return std::vector<std::string>{std::to_string(d.firstFrame) + " " + std::to_string(d.lastFrame)};
      });
}

Key<Dynamics> windKey() {
  return repeatable(customKey<Dynamics>(
      {"Wind", "m/s²", "an acceleration on the hair from FRAME on; linear: ramped from the previous key"},
      "FRAME ax ay az [hold | linear]", "",
      [](SectionReader& r, Dynamics& d) {
        for (const ConfigLine* line : r.lines("Wind")) {
          if (line->values.size() != 4 && line->values.size() != 5)
            throw r.error(*line, "Wind takes FRAME ax ay az and, optionally, hold or linear");
          WindKey w;
          w.frame = frameOf(r, *line);
          for (int i = 0; i < 3; ++i)
            w.acceleration[i] = r.checkReal(*line, 1 + i, Range::closed(-1e4, 1e4), "acceleration");
          if (line->values.size() == 5) {
            const std::string mode = toLower(line->values[4]);
            if (mode != "hold" && mode != "linear")
              throw r.error(*line, "'" + line->values[4] + "' is not hold or linear");
            w.linear = mode == "linear";
          }
          w.where = line->where;
          d.wind.push_back(w);
        }
        std::stable_sort(d.wind.begin(), d.wind.end(),
                         [](const WindKey& a, const WindKey& b) { return a.frame < b.frame; });
        for (size_t i = 1; i < d.wind.size(); ++i)
          if (d.wind[i].frame == d.wind[i - 1].frame)
            throw InputError(d.wind[i].where, "a second Wind key at frame " + formatReal(d.wind[i].frame) +
                                                  " (the first is at " + d.wind[i - 1].where.str() + ")");
      },
      [](const Dynamics& d) {
        std::vector<std::string> lines;
        for (const WindKey& w : d.wind)
          lines.push_back(formatReal(w.frame) + " " + join(w.acceleration) +
                          (w.linear ? " linear" : " hold"));
        return lines;
      }));
}

Key<Dynamics> headKeyKey() {
  return repeatable(customKey<Dynamics>(
      {"HeadKey", "m, degrees",
       "the head's pose at FRAME: a translation, and rotations about x, y, z (in that order) about its "
       "centre"},
      "FRAME tx ty tz rx ry rz", "",
      [](SectionReader& r, Dynamics& d) {
        for (const ConfigLine* line : r.lines("HeadKey")) {
          if (line->values.size() != 7) throw r.error(*line, "HeadKey takes FRAME tx ty tz rx ry rz");
          HeadKey k;
          k.frame = frameOf(r, *line);
          for (int i = 0; i < 3; ++i)
            k.translation[i] = r.checkReal(*line, 1 + i, Range::closed(-1e4, 1e4), "translation");
          for (int i = 0; i < 3; ++i)
            k.rotation[i] = r.checkReal(*line, 4 + i, Range::closed(-36000, 36000), "rotation");
          k.where = line->where;
          d.headKeys.push_back(k);
        }
        std::stable_sort(d.headKeys.begin(), d.headKeys.end(),
                         [](const HeadKey& a, const HeadKey& b) { return a.frame < b.frame; });
        for (size_t i = 1; i < d.headKeys.size(); ++i)
          if (d.headKeys[i].frame == d.headKeys[i - 1].frame)
            throw InputError(d.headKeys[i].where, "a second HeadKey at frame " +
                                                      formatReal(d.headKeys[i].frame) + " (the first is at " +
                                                      d.headKeys[i - 1].where.str() + ")");
      },
      [](const Dynamics& d) {
        std::vector<std::string> lines;
        for (const HeadKey& k : d.headKeys)
          lines.push_back(formatReal(k.frame) + " " + join(k.translation) + " " + join(k.rotation));
        return lines;
      }));
}

Key<Dynamics> headCentreKey() {
  return customKey<Dynamics>(
      {"HeadCentre", "m",
       "the point the head turns about; auto = the head shape's centre (docs/configs.md; else the origin)"},
      "auto | x y z", "",
      [](SectionReader& r, Dynamics& d) {
        const ConfigLine* line = r.line("HeadCentre");
        if (!line) return;
        if (line->values.size() == 1 && toLower(line->values[0]) == "auto") return;
        if (line->values.size() != 3) throw r.error(*line, "HeadCentre takes auto or x y z");
        d.headCentreAuto = false;
        for (int i = 0; i < 3; ++i)
          d.headCentre[i] = r.checkReal(*line, i, Range::closed(-1e4, 1e4), "centre");
      },
      [](const Dynamics& d) {
        return std::vector<std::string>{d.headCentreAuto ? std::string("auto") : join(d.headCentre)};
      });
}

Key<Dynamics> inertiaKey() {
  return customKey<Dynamics>(
      {"Inertia", "",
       "segment i of k has (k/i)^p the inertia of its mass at the hair's length, times f for the "
       "first n "
       "segments"},
      "p [f n]", "p in [0, 4], f > 0, n >= 0",
      [](SectionReader& r, Dynamics& d) {
        const ConfigLine* line = r.line("Inertia");
        if (!line) return;
        if (line->values.size() != 1 && line->values.size() != 3)
          throw r.error(*line,
                        "Inertia takes the exponent p and, optionally, a factor f for the first n segments");
        d.inertiaExponent = r.checkReal(*line, 0, Range::closed(0.0, 4.0), "exponent");
        if (line->values.size() == 3) {
          d.rootInertia = r.checkReal(*line, 1, {0.0, 1e6, true, false}, "factor");
          const double n = r.checkReal(*line, 2, Range::closed(0.0, 100000.0), "segments");
          if (n != std::floor(n)) throw r.error(*line, "the number of segments must be a whole number");
          d.rootSegments = int(n);
        }
      },
      [](const Dynamics& d) {
        return std::vector<std::string>{formatReal(d.inertiaExponent) + " " + formatReal(d.rootInertia) +
                                        " " + std::to_string(d.rootSegments)};
      });
}

Key<Dynamics> pseudoForceKey() {
  return customKey<Dynamics>(
      {"PseudoForce", "-, -, m",
       "within reach of the head shape, a force with D·F < α|D||F| (into the head) is scaled by "
       "ε"},
      "alpha epsilon reach", "α in [-1, 1], ε in [0, 1], reach >= 0",
      [](SectionReader& r, Dynamics& d) {
        const ConfigLine* line = r.line("PseudoForce");
        if (!line) return;
        if (line->values.size() != 3) throw r.error(*line, "PseudoForce takes alpha epsilon reach");
        d.pseudoAlpha = r.checkReal(*line, 0, Range::closed(-1.0, 1.0), "alpha");
        d.pseudoEpsilon = r.checkReal(*line, 1, Range::closed(0.0, 1.0), "epsilon");
        d.pseudoReach = r.checkReal(*line, 2, Range::closed(0.0, 10.0), "reach");
      },
      [](const Dynamics& d) {
        return std::vector<std::string>{formatReal(d.pseudoAlpha) + " " + formatReal(d.pseudoEpsilon) + " " +
                                        formatReal(d.pseudoReach)};
      });
}

Key<Dynamics> fluctuationKey() {
  return customKey<Dynamics>(
      {"Fluctuation", "radians, frames",
       "random turns of each segment up to the amplitude (the most at the tip), drawn once every N "
       "frames"},
      "amplitude N", "amplitude in [0, 1], N >= 1",
      [](SectionReader& r, Dynamics& d) {
        const ConfigLine* line = r.line("Fluctuation");
        if (!line) return;
        if (line->values.size() != 2)
          throw r.error(*line, "Fluctuation takes an amplitude and every how many frames");
        d.fluctuation = r.checkReal(*line, 0, Range::closed(0.0, 1.0), "amplitude");
        const double n = r.checkReal(*line, 1, Range::closed(1.0, 1e6), "frames");
        if (n != std::floor(n)) throw r.error(*line, "the number of frames must be a whole number");
        d.fluctuationEvery = int(n);
      },
      [](const Dynamics& d) {
        return std::vector<std::string>{formatReal(d.fluctuation) + " " + std::to_string(d.fluctuationEvery)};
      });
}

Key<Dynamics> restFrequencyKey() {
  return customKey<Dynamics>(
      {"RestFrequency", "Hz",
       "the angular spring that holds the styled shape (0 = none); auto = the hair's first bending "
       "mode"},
      "auto | Hz", "[0, 1000]",
      [](SectionReader& r, Dynamics& d) {
        const ConfigLine* line = r.line("RestFrequency");
        if (!line) return;
        if (line->values.size() != 1) throw r.error(*line, "RestFrequency takes auto or a frequency in Hz");
        if (toLower(line->values[0]) == "auto") return;
        d.restFrequencyAuto = false;
        d.restFrequency = r.checkReal(*line, 0, Range::closed(0.0, 1000.0), "frequency");
      },
      [](const Dynamics& d) {
        return std::vector<std::string>{d.restFrequencyAuto ? std::string("auto")
                                                            : formatReal(d.restFrequency)};
      });
}

// A value that defaults to one computed from other keys: `auto`, or a number in `range`.
Key<Dynamics> autoRealKey(KeyText t, std::string what, bool Dynamics::*isAuto, double Dynamics::*member,
                          Range range) {
  const std::string name = t.name;
  return customKey<Dynamics>(
      t, "auto | " + what, range.describe(),
      [=](SectionReader& r, Dynamics& d) {
        const ConfigLine* line = r.line(name);
        if (!line) return;
        if (line->values.size() != 1) throw r.error(*line, name + " takes auto or a number");
        if (toLower(line->values[0]) == "auto") return;
        d.*isAuto = false;
        d.*member = r.checkReal(*line, 0, range, what);
      },
      [=](const Dynamics& d) {
        return std::vector<std::string>{d.*isAuto ? std::string("auto") : formatReal(d.*member)};
      });
}

Key<Dynamics> densitySpacingsKey() {
  return customKey<Dynamics>(
      {"DensitySpacings", "m",
       "the density grids' spacings, coarse to fine; the next takes over when the energy at this "
       "one falls to DensityRefine of its start"},
      "h1 [h2 ...]", "[0.0001, 1], not increasing",
      [](SectionReader& r, Dynamics& d) {
        if (!r.has("DensitySpacings")) return;
        // From a tenth of a millimetre (a few hair widths; finer grids resolve single hairs, not a
        // density) to a metre (a whole head in one cell). Their memory is simulate's estimate's.
        d.densitySpacings = r.realList("DensitySpacings", Range::closed(1e-4, 1.0));
        for (size_t i = 1; i < d.densitySpacings.size(); ++i)
          if (d.densitySpacings[i] > d.densitySpacings[i - 1])
            throw InputError(r.where("DensitySpacings"),
                             "DensitySpacings go from coarse to fine: " + formatReal(d.densitySpacings[i]) +
                                 " follows the finer " + formatReal(d.densitySpacings[i - 1]));
      },
      [](const Dynamics& d) {
        std::string out;
        for (double h : d.densitySpacings) out += (out.empty() ? "" : " ") + formatReal(h);
        return std::vector<std::string>{out};
      });
}

// The keys only one model reads (declared with `only`): naming one for the other model is an error (a key
// that is read is used).
void checkModelKeys(SectionReader& r, const Dynamics& d) {
  for (const KeySpec& key : dynamicsKeys().spec.keys) {
    if (key.models.empty() || !r.has(key.name) ||
        std::find(key.models.begin(), key.models.end(), name(d.model)) != key.models.end())
      continue;
    std::string models;
    for (const std::string& model : key.models) models += (models.empty() ? "" : " or ") + model;
    throw InputError(r.where(key.name), key.name + " is a key of Model " + models +
                                            ", and this Dynamics Info is Model " + name(d.model) +
                                            "; remove it or change the Model");
  }
  for (const char* key : {"DensitySpacings", "DensityRefine"})
    if (r.has(key) && !d.densityTarget.given())
      throw InputError(r.where(key),
                       std::string(key) +
                           " sets up the density grids of a DensityTarget, and none is named; add "
                           "`DensityTarget FILE` (a hair cache) or remove it");
  if (r.has("SmoothingSpacing") && !(d.velocitySmoothing > 0.0))
    throw InputError(r.where("SmoothingSpacing"),
                     "SmoothingSpacing is the grid of VelocitySmoothing, which is 0; set VelocitySmoothing "
                     "above 0 or remove it");
  if (d.densityStrength > 0.0 && !d.densityTarget.given())
    throw InputError(r.where("DensityStrength"),
                     "DensityStrength pushes the hair toward a DensityTarget, and none is named; add "
                     "`DensityTarget FILE` (a hair cache)");
}

// A Dynamics key that only `model` reads.
Key<Dynamics> only(DynamicsModel model, Key<Dynamics> key) {
  return onlyFor<Dynamics>({name(model)}, std::move(key));
}

Section<Dynamics> makeDynamics() {
  using D = Dynamics;
  return makeSection<D>(
      "Dynamics", "Dynamics Info", "DynamicsInfo",
      {choiceKey<D, DynamicsModel>({"Model", "", "anjyo (Anjyo et al. §3) or springs (Petrovic et al. §5)"},
                                   &D::model, {std::begin(kDynamicsModels), std::end(kDynamicsModels)}),
       framesKey(),
       // From a frame a second (a time-lapse) to 10000 (high-speed footage): a step of more than a second
       // is no shot's, and 1e-20 frames/s overflows the step.
       realKey<D>({"FrameRate", "frames/s", "frames per second"}, &D::frameRate, Range::closed(1.0, 10000.0)),
       integerKey<D>({"Substeps", "", "integration steps per frame"}, &D::substeps, 1, 1000),
       realKey<D>({"Damping", "1/s", "the rate at which motion dies away (air, hair on hair)"}, &D::damping,
                  Range::closed(0.0, 1000.0)),
       windKey(), headKeyKey(), headCentreKey(),
       only(DynamicsModel::kSprings,
            autoRealKey({"Gravity", "N/kg",
                         "the gravity the moving hair feels, along -y; auto = Hairstyle's Gravity"},
                        "N/kg", &D::gravityAuto, &D::gravity, Range::closed(0.0, 1000.0))),
       only(DynamicsModel::kAnjyo, inertiaKey()), only(DynamicsModel::kAnjyo, pseudoForceKey()),
       only(DynamicsModel::kAnjyo, fluctuationKey()), only(DynamicsModel::kAnjyo, restFrequencyKey()),
       only(DynamicsModel::kSprings,
            autoRealKey({"StretchStiffness", "N",
                         "a segment's force per unit strain, E·A; auto = Young × π a b (effectively "
                         "inextensible)"},
                        "N", &D::stretchStiffnessAuto, &D::stretchStiffness, Range::positive())),
       only(DynamicsModel::kSprings,
            autoRealKey({"BendStiffness", "N·m²", "E·I; auto = Young × π a b³/4"}, "N·m²",
                        &D::bendStiffnessAuto, &D::bendStiffness, Range::nonNegative())),
       only(DynamicsModel::kSprings,
            autoRealKey({"TwistStiffness", "N·m²", "μ·J; auto = Young/(2(1 + Poisson)) × π a b (a² + b²)/4"},
                        "N·m²", &D::twistStiffnessAuto, &D::twistStiffness, Range::nonNegative())),
       only(DynamicsModel::kSprings,
            realKey<D>({"VelocitySmoothing", "",
                        "the fraction of each particle's departure from the smoothed grid velocity "
                        "removed per frame (Petrovic et al. §5.1)"},
                       &D::velocitySmoothing, Range::closed(0.0, 1.0))),
       only(DynamicsModel::kSprings, realKey<D>({"SmoothingSpacing", "m", "the velocity grid's spacing"},
                                                &D::smoothingSpacing, {0.0, 10.0, true, false})),
       only(DynamicsModel::kSprings,
            pathKey<D>({"DensityTarget", "",
                        "a hair cache whose density the hair is pushed toward (Petrovic et al. §5.2)"},
                       &D::densityTarget)),
       only(DynamicsModel::kSprings,
            realKey<D>({"DensityStrength", "m/s²",
                        "the density force (Petrovic et al. §5.2) as a point's acceleration where the "
                        "density differs from the target's by its mean from one node to the next; 0 = none"},
                       &D::densityStrength, Range::closed(0.0, 1e9))),
       only(DynamicsModel::kSprings, densitySpacingsKey()),
       only(DynamicsModel::kSprings,
            realKey<D>({"DensityRefine", "",
                        "a density spacing hands over to the next finer one when its energy falls "
                        "to this fraction of its start"},
                       &D::densityRefine, {0.0, 1.0, true, false}))},
      checkModelKeys);
}

}  // namespace

const Section<Setup>& setupKeys() {
  static const Section<Setup> section = makeSetup();
  return section;
}
const Section<Hairstyle>& hairstyleKeys() {
  static const Section<Hairstyle> section = makeHairstyle();
  return section;
}
const Section<Collision>& collisionKeys() {
  static const Section<Collision> section = makeCollision();
  return section;
}
const Section<Visuality>& visualityKeys() {
  static const Section<Visuality> section = makeVisuality();
  return section;
}
const Section<RenderSettings>& renderKeys() {
  static const Section<RenderSettings> section = makeRender();
  return section;
}

const Section<Dynamics>& dynamicsKeys() {
  static const Section<Dynamics> section = makeDynamics();
  return section;
}

const SectionList& allSections() {
  static const SectionList sections = {&setupKeys().spec,     &hairstyleKeys().spec, &collisionKeys().spec,
                                       &visualityKeys().spec, &renderKeys().spec,    &dynamicsKeys().spec};
  return sections;
}

Setup readSetup(const ConfigText& text, const std::vector<Override>& overrides) {
  return readSection(setupKeys(), text, overrides);
}
Hairstyle readHairstyle(const ConfigText& text, const std::vector<Override>& overrides) {
  return readSection(hairstyleKeys(), text, overrides);
}
Collision readCollision(const ConfigText& text, const std::vector<Override>& overrides) {
  return readSection(collisionKeys(), text, overrides);
}
Visuality readVisuality(const ConfigText& text, const std::vector<Override>& overrides) {
  return readSection(visualityKeys(), text, overrides);
}
RenderSettings readRender(const ConfigText& text, const std::vector<Override>& overrides) {
  return readSection(renderKeys(), text, overrides);
}
Dynamics readDynamics(const ConfigText& text, const std::vector<Override>& overrides) {
  return readSection(dynamicsKeys(), text, overrides);
}

std::string Config::canonicalText() const {
  // Dynamics only when the Setup names a Dynamics Info, so that a still coupe's digest is the one it
  // had before hairgen could simulate.
  // Then the inputs whose bytes shape the output, by content (inputContent): a line each.
  std::string inputs;
  for (const auto& [key, content] : inputContent) inputs += "Input." + key + " " + content + "\n";
  return setupKeys().canonicalText(setup) + hairstyleKeys().canonicalText(hairstyle) +
         collisionKeys().canonicalText(collision) + visualityKeys().canonicalText(visuality) +
         renderKeys().canonicalText(render) + (dynamics.given ? dynamicsKeys().canonicalText(dynamics) : "") +
         inputs;
}

}  // namespace hairgen
