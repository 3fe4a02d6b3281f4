// Triangle meshes: the wick (every vertex a follicle) and the head.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>

namespace hairgen {

// A triangle mesh as flat arrays. Positions in metres, +y up, face along +z (DESIGN §2).
struct Mesh {
  std::vector<glm::vec3> positions;
  std::vector<glm::vec3> normals;     // one unit normal per vertex (same size as positions)
  std::vector<glm::uvec3> triangles;  // counter-clockwise seen from outside
  std::vector<glm::vec2> uvs;         // one per vertex, or empty when the mesh has none

  size_t vertexCount() const { return positions.size(); }
  size_t triangleCount() const { return triangles.size(); }
};

// Area-weighted vertex normals (the sum of the incident triangles' cross products, normalised).
// A vertex no triangle touches gets the zero vector.
std::vector<glm::vec3> areaWeightedNormals(const std::vector<glm::vec3>& positions,
                                           const std::vector<glm::uvec3>& triangles);

double triangleArea(const Mesh& mesh, size_t triangle);  // square metres
double surfaceArea(const Mesh& mesh);                    // square metres

struct Bounds {
  glm::vec3 min{0.0f};
  glm::vec3 max{0.0f};
};
Bounds bounds(std::span<const glm::vec3> points);  // {0,0} for no points

}  // namespace hairgen
