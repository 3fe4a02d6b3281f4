// What a stage's output must satisfy whatever its numbers, checked by the stage goldens
// (tests/golden_test.sh) beside the comparison with their reference cache. Each check reads its caches
// with the readers, which refuse a NaN or an infinity anywhere (Strands::validate), so every check also
// says the cache holds no non-finite value.
//
//   stage_invariants roots-on-mesh CACHE MESH.obj        every strand's root lies on the mesh (the scalp)
//   stage_invariants segments-kept CACHE REST REL        the strands of REST, each segment as long as
//                                                        REST's within REL (relative)
//   stage_invariants points-kept CACHE INPUT             INPUT's points bit for bit, with unit normals
//
// Prints one line per check; exits 0 when it holds, 1 with the first offending strand when it does not,
// 2 on bad usage or an unreadable file.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <string>

#include <glm/glm.hpp>

#include "libcore/io/hair_cache.h"
#include "libcore/io/obj_io.h"
#include "libcore/util/error.h"
#include "tests/geometry_util.h"

namespace hairgen {
namespace {

// A root lies on the scalp when it is within 1 µm of a triangle: grow puts it on a vertex and interpolate
// at barycentric coordinates of a triangle, both in float, whose spacing at head scale is 1.5e-8 m; a
// root carried off the scalp by anything else is millimetres away.
constexpr double kOnMesh = 1.0e-6;

// A normal is unit length within float's round-off of a normalisation.
constexpr double kUnitNormal = 1.0e-5;

int verdict(bool holds, const std::string& what) {
  std::cout << (holds ? "holds: " : "FAILS: ") << what << "\n";
  return holds ? 0 : 1;
}

std::string number(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3g", v);
  return text;
}

int rootsOnMesh(const Strands& hair, const Mesh& mesh) {
  double worst = 0.0;
  size_t worstStrand = 0;
  for (size_t s = 0; s < hair.strandCount(); ++s) {
    if (hair.pointsOf(s) == 0) continue;
    const glm::dvec3 root(hair.points[hair.firstPoint[s]]);
    double nearest = INFINITY;
    for (const glm::uvec3& t : mesh.triangles)
      nearest = std::min(nearest, test::distanceToTriangle(root, glm::dvec3(mesh.positions[t.x]),
                                                           glm::dvec3(mesh.positions[t.y]),
                                                           glm::dvec3(mesh.positions[t.z])));
    if (nearest > worst) worst = nearest, worstStrand = s;
  }
  return verdict(worst <= kOnMesh, std::to_string(hair.strandCount()) + " roots on the mesh (farthest " +
                                       number(worst) + " m, strand " + std::to_string(worstStrand) +
                                       "; limit " + number(kOnMesh) + " m)");
}

int segmentsKept(const Strands& hair, const Strands& rest, double relative) {
  if (hair.strandCount() != rest.strandCount() || hair.firstPoint != rest.firstPoint)
    return verdict(false, "the strands and points per strand of the rest cache");
  double worst = 0.0;
  size_t worstStrand = 0;
  for (size_t s = 0; s < hair.strandCount(); ++s)
    for (uint32_t i = hair.firstPoint[s] + 1; i < hair.firstPoint[s + 1]; ++i) {
      const double restLength = glm::length(glm::dvec3(rest.points[i]) - glm::dvec3(rest.points[i - 1]));
      const double length = glm::length(glm::dvec3(hair.points[i]) - glm::dvec3(hair.points[i - 1]));
      const double change = std::abs(length - restLength) / restLength;
      if (change > worst) worst = change, worstStrand = s;
    }
  return verdict(worst <= relative, "segment lengths of the rest cache (largest change " + number(worst) +
                                        ", strand " + std::to_string(worstStrand) + "; limit " +
                                        number(relative) + ")");
}

int pointsKept(const Strands& hair, const Strands& input) {
  if (hair.firstPoint != input.firstPoint || hair.points != input.points)
    return verdict(false, "the input's strands and points, bit for bit");
  double worst = hair.normals.empty() ? INFINITY : 0.0;
  for (const glm::vec3& n : hair.normals) worst = std::max(worst, std::abs(glm::length(glm::dvec3(n)) - 1.0));
  return verdict(worst <= kUnitNormal,
                 "the input's points bit for bit, and unit normals (largest |length - 1| " + number(worst) +
                     "; limit " + number(kUnitNormal) + ")");
}

int run(int argc, char** argv) {
  const std::string check = argc > 1 ? argv[1] : "";
  if (check == "roots-on-mesh" && argc == 4) return rootsOnMesh(readStrands(argv[2]), readObj(argv[3]));
  if (check == "segments-kept" && argc == 5)
    return segmentsKept(readStrands(argv[2]), readStrands(argv[3]), std::stod(argv[4]));
  if (check == "points-kept" && argc == 4) return pointsKept(readStrands(argv[2]), readStrands(argv[3]));
  std::cerr << "usage: stage_invariants roots-on-mesh CACHE MESH.obj | segments-kept CACHE REST REL | "
               "points-kept CACHE INPUT\n";
  return 2;
}

}  // namespace
}  // namespace hairgen

int main(int argc, char** argv) {
  try {
    return hairgen::run(argc, argv);
  } catch (const std::exception& e) {
    std::cerr << "stage_invariants: " << e.what() << "\n";
    return 2;
  }
}
