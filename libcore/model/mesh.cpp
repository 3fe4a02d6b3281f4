#include "libcore/model/mesh.h"

#include <limits>

namespace hairgen {

std::vector<glm::vec3> areaWeightedNormals(const std::vector<glm::vec3>& positions,
                                           const std::vector<glm::uvec3>& triangles) {
  // Accumulate in double: a scalp of thousands of tiny triangles loses digits in float.
  std::vector<glm::dvec3> sum(positions.size(), glm::dvec3(0.0));
  for (const glm::uvec3& t : triangles) {
    glm::dvec3 a(positions[t.x]), b(positions[t.y]), c(positions[t.z]);
    glm::dvec3 n = glm::cross(b - a, c - a);  // length = twice the area: the weighting we want
    sum[t.x] += n;
    sum[t.y] += n;
    sum[t.z] += n;
  }
  std::vector<glm::vec3> normals(positions.size(), glm::vec3(0.0f));
  for (size_t i = 0; i < sum.size(); ++i) {
    double length = glm::length(sum[i]);
    if (length > 0.0) normals[i] = glm::vec3(sum[i] / length);
  }
  return normals;
}

double triangleArea(const Mesh& mesh, size_t triangle) {
  const glm::uvec3& t = mesh.triangles[triangle];
  glm::dvec3 a(mesh.positions[t.x]), b(mesh.positions[t.y]), c(mesh.positions[t.z]);
  return 0.5 * glm::length(glm::cross(b - a, c - a));
}

double surfaceArea(const Mesh& mesh) {
  double area = 0.0;
  for (size_t i = 0; i < mesh.triangles.size(); ++i) area += triangleArea(mesh, i);
  return area;
}

Bounds bounds(std::span<const glm::vec3> points) {
  if (points.empty()) return {};
  Bounds b{glm::vec3(std::numeric_limits<float>::max()), glm::vec3(std::numeric_limits<float>::lowest())};
  for (const glm::vec3& p : points) {
    b.min = glm::min(b.min, p);
    b.max = glm::max(b.max, p);
  }
  return b;
}

}  // namespace hairgen
