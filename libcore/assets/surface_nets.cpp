#include "libcore/assets/surface_nets.h"

#include <array>
#include <cmath>

namespace hairgen {

glm::dvec3 sdfNormal(const DistanceFn& sdf, const glm::dvec3& p, double h) {
  glm::dvec3 g(sdf(p + glm::dvec3(h, 0, 0)) - sdf(p - glm::dvec3(h, 0, 0)),
               sdf(p + glm::dvec3(0, h, 0)) - sdf(p - glm::dvec3(0, h, 0)),
               sdf(p + glm::dvec3(0, 0, h)) - sdf(p - glm::dvec3(0, 0, h)));
  double length = glm::length(g);
  return length > 0.0 ? g / length : glm::dvec3(0.0, 1.0, 0.0);
}

Mesh surfaceNets(const DistanceFn& sdf, const glm::dvec3& lo, const glm::dvec3& hi, double spacing) {
  const glm::ivec3 n = glm::ivec3(glm::ceil((hi - lo) / spacing)) + 1;  // nodes per axis
  auto node = [&](int i, int j, int k) { return (static_cast<size_t>(k) * n.y + j) * n.x + i; };
  auto at = [&](int i, int j, int k) { return lo + spacing * glm::dvec3(i, j, k); };

  std::vector<double> value(static_cast<size_t>(n.x) * n.y * n.z);
  for (int k = 0; k < n.z; ++k)
    for (int j = 0; j < n.y; ++j)
      for (int i = 0; i < n.x; ++i) value[node(i, j, k)] = sdf(at(i, j, k));

  // One vertex per cell with a sign change; cells are indexed like their lowest node.
  std::vector<int> cellVertex(value.size(), -1);
  Mesh mesh;
  static const std::array<std::array<int, 2>, 12> edges = {
      {{0, 1}, {2, 3}, {4, 5}, {6, 7}, {0, 2}, {1, 3}, {4, 6}, {5, 7}, {0, 4}, {1, 5}, {2, 6}, {3, 7}}};
  for (int k = 0; k + 1 < n.z; ++k)
    for (int j = 0; j + 1 < n.y; ++j)
      for (int i = 0; i + 1 < n.x; ++i) {
        double f[8];
        glm::dvec3 p[8];
        bool inside = false, outside = false;
        for (int c = 0; c < 8; ++c) {
          int di = c & 1, dj = (c >> 1) & 1, dk = (c >> 2) & 1;
          f[c] = value[node(i + di, j + dj, k + dk)];
          p[c] = at(i + di, j + dj, k + dk);
          (f[c] < 0.0 ? inside : outside) = true;
        }
        if (!inside || !outside) continue;
        glm::dvec3 sum(0.0);
        int crossings = 0;
        for (const auto& e : edges) {
          if ((f[e[0]] < 0.0) == (f[e[1]] < 0.0)) continue;
          double t = f[e[0]] / (f[e[0]] - f[e[1]]);
          sum += p[e[0]] + t * (p[e[1]] - p[e[0]]);
          ++crossings;
        }
        glm::dvec3 v = sum / double(crossings);
        // Newton steps onto the surface, kept within the cell so the net cannot fold.
        for (int step = 0; step < 3; ++step) {
          glm::dvec3 g = sdfNormal(sdf, v, 0.1 * spacing);
          v = glm::clamp(v - sdf(v) * g, p[0], p[7]);
        }
        cellVertex[node(i, j, k)] = static_cast<int>(mesh.positions.size());
        mesh.positions.push_back(glm::vec3(v));
        mesh.normals.push_back(glm::vec3(sdfNormal(sdf, v, 0.25 * spacing)));
      }

  // One quad per grid edge with a sign change, around the four cells that share the edge, wound so its
  // normal points from inside to outside. Axis a with (u, v) such that u × v = a.
  const glm::ivec3 unit[3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  for (int a = 0; a < 3; ++a) {
    const glm::ivec3 u = unit[(a + 1) % 3], w = unit[(a + 2) % 3];
    for (int k = 1; k + 1 < n.z; ++k)
      for (int j = 1; j + 1 < n.y; ++j)
        for (int i = 1; i + 1 < n.x; ++i) {
          glm::ivec3 base(i, j, k), next = base + unit[a];
          if (next.x >= n.x || next.y >= n.y || next.z >= n.z) continue;
          bool first = value[node(base.x, base.y, base.z)] < 0.0;
          if (first == (value[node(next.x, next.y, next.z)] < 0.0)) continue;
          glm::ivec3 cells[4] = {base - u - w, base - w, base, base - u};
          int q[4];
          bool ok = true;
          for (int c = 0; c < 4; ++c) {
            q[c] = cellVertex[node(cells[c].x, cells[c].y, cells[c].z)];
            ok = ok && q[c] >= 0;
          }
          if (!ok) continue;
          if (!first) std::swap(q[1], q[3]);
          // Split along the shorter diagonal.
          float d02 = glm::length(mesh.positions[q[0]] - mesh.positions[q[2]]);
          float d13 = glm::length(mesh.positions[q[1]] - mesh.positions[q[3]]);
          if (d02 <= d13) {
            mesh.triangles.push_back(glm::uvec3(q[0], q[1], q[2]));
            mesh.triangles.push_back(glm::uvec3(q[0], q[2], q[3]));
          } else {
            mesh.triangles.push_back(glm::uvec3(q[0], q[1], q[3]));
            mesh.triangles.push_back(glm::uvec3(q[1], q[2], q[3]));
          }
        }
  }
  return mesh;
}

}  // namespace hairgen
