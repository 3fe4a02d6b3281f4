#include "libcore/io/hair_diff.h"

#include <cmath>
#include <cstdio>
#include <numbers>

#include "libcore/util/text.h"

namespace hairgen {
namespace {

std::string number(double v) {
  return formatSignificant(v, 6);
}

// Exactly, since roots are compared bit for bit.
std::string point(const glm::vec3& p) {
  return "(" + formatFloat(p.x) + ", " + formatFloat(p.y) + ", " + formatFloat(p.z) + ")";
}

HairDiff failed(HairDiff d, std::string reason) {
  d.reason = std::move(reason);
  d.code = ExitCode::kDiffFailed;
  return d;
}

// Why B's structure is not A's, or "" when strand count, points per strand, roots and ids match.
std::string structureDifference(const Strands& a, const Strands& b) {
  if (a.strandCount() != b.strandCount())
    return "the reference has " + std::to_string(a.strandCount()) + " strands, the other " +
           std::to_string(b.strandCount());
  for (size_t s = 0; s < a.strandCount(); ++s) {
    if (a.pointsOf(s) != b.pointsOf(s))
      return "strand " + std::to_string(s) + " has " + std::to_string(a.pointsOf(s)) +
             " points in the reference, " + std::to_string(b.pointsOf(s)) + " in the other";
    if (a.pointsOf(s) > 0 && a.points[a.firstPoint[s]] != b.points[b.firstPoint[s]])
      return "strand " + std::to_string(s) + "'s root moved: " + point(a.points[a.firstPoint[s]]) +
             " in the reference, " + point(b.points[b.firstPoint[s]]) + " in the other";
  }
  if (!a.strandId.empty()) {
    if (b.strandId.empty()) return "the other has no strand ids";
    for (size_t s = 0; s < a.strandCount(); ++s)
      if (a.strandId[s] != b.strandId[s])
        return "strand " + std::to_string(s) + " has id " + std::to_string(a.strandId[s]) +
               " in the reference, " + std::to_string(b.strandId[s]) + " in the other";
  }
  if (!a.normals.empty() && b.normals.empty()) return "the other has no normals";
  if (!a.colors.empty() && b.colors.empty()) return "the other has no colours";
  return "";
}

bool finite(const glm::vec3& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

// Why B holds a value no cache may (the readers refuse them; strands built in memory may not), or "".
std::string nonFinite(const Strands& b) {
  for (const auto* array : {&b.normals, &b.colors})
    for (size_t i = 0; i < array->size(); ++i)
      if (!finite((*array)[i]))
        return "the other has a non-finite normal or colour at point " + std::to_string(i);
  for (size_t i = 0; i < b.points.size(); ++i)
    if (!finite(b.points[i])) return "the other has a non-finite point at index " + std::to_string(i);
  return "";
}

double angleDegrees(const glm::vec3& a, const glm::vec3& b) {
  const glm::dvec3 u(a), v(b);
  return std::atan2(glm::length(glm::cross(u, v)), glm::dot(u, v)) * 180.0 / std::numbers::pi;
}

}  // namespace

HairDiff diffHair(const Strands& a, const Strands& b, const HairDiffTolerances& tolerances) {
  HairDiff d;
  d.strands = a.strandCount();
  d.points = a.pointCount();
  if (std::string why = structureDifference(a, b); !why.empty()) return failed(d, why);
  if (std::string why = nonFinite(b); !why.empty()) return failed(d, why);
  d.structureMatches = true;

  double sum = 0.0;
  for (size_t s = 0; s < a.strandCount(); ++s)
    for (uint32_t i = a.firstPoint[s]; i < a.firstPoint[s + 1]; ++i) {
      const double distance = glm::length(glm::dvec3(a.points[i]) - glm::dvec3(b.points[i]));
      sum += distance;
      if (distance > d.maxDistance) {
        d.maxDistance = distance;
        d.worstStrand = s;
        d.worstPoint = i - a.firstPoint[s];
      }
    }
  d.meanDistance = a.pointCount() == 0 ? 0.0 : sum / double(a.pointCount());
  d.normalsCompared = !a.normals.empty();
  for (size_t i = 0; i < a.normals.size(); ++i)
    d.maxAngleDegrees = std::max(d.maxAngleDegrees, angleDegrees(a.normals[i], b.normals[i]));
  d.colorsCompared = !a.colors.empty();
  for (size_t i = 0; i < a.colors.size(); ++i)
    for (int c = 0; c < 3; ++c)
      d.maxColor = std::max(d.maxColor, std::abs(double(a.colors[i][c]) - double(b.colors[i][c])));

  if (d.maxDistance > tolerances.distance)
    return failed(d, "point " + std::to_string(d.worstPoint) + " of strand " + std::to_string(d.worstStrand) +
                         " is " + number(d.maxDistance) + " m from the reference's (tolerance " +
                         number(tolerances.distance) + " m)");
  if (d.maxAngleDegrees > tolerances.angleDegrees)
    return failed(d, "normals turn by up to " + number(d.maxAngleDegrees) + " degrees (tolerance " +
                         number(tolerances.angleDegrees) + ")");
  if (d.maxColor > kHairDiffColorTolerance)
    return failed(d, "colours differ by up to " + number(d.maxColor) + " (tolerance " +
                         number(kHairDiffColorTolerance) + ")");
  return d;
}

}  // namespace hairgen
