// The keys of Collision Info (the spheres, ellipsoids and boxes hair collides with), declared once;
// keys.cpp makes the section from them, key_helpers.h holds what the section files share.
#include "libcore/config/key_helpers.h"

namespace hairgen::keydecl {

namespace {

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

}  // namespace

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

}  // namespace hairgen::keydecl
