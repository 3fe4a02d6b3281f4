#include "libcore/volume/density_target.h"

namespace hairgen {

glm::dvec3 densityForce(const Grid& d, const glm::dvec3& p) {
  const glm::dvec3 g = (p - d.origin) / d.voxel;
  const glm::ivec3 c = glm::ivec3(glm::floor(g));
  if (glm::any(glm::lessThan(c, glm::ivec3(0))) || glm::any(glm::greaterThanEqual(c + 1, d.size)))
    return glm::dvec3(0.0);
  const glm::dvec3 f = g - glm::dvec3(c);
  auto at = [&](int dx, int dy, int dz) { return double(d.at(c.x + dx, c.y + dy, c.z + dz)); };
  // The memo's weights of the cell's lower grid lines, a = 1 − f: F_x differences D_d across the cell
  // in x, weighted by the point's tent weights in y and z; F_y and F_z likewise.
  const glm::dvec3 a = 1.0 - f;
  glm::dvec3 force(0.0);
  if (f.x != 0.0)
    force.x = a.y * a.z * (at(0, 0, 0) - at(1, 0, 0)) + (1 - a.y) * a.z * (at(0, 1, 0) - at(1, 1, 0)) +
              a.y * (1 - a.z) * (at(0, 0, 1) - at(1, 0, 1)) +
              (1 - a.y) * (1 - a.z) * (at(0, 1, 1) - at(1, 1, 1));
  if (f.y != 0.0)
    force.y = a.x * a.z * (at(0, 0, 0) - at(0, 1, 0)) + (1 - a.x) * a.z * (at(1, 0, 0) - at(1, 1, 0)) +
              a.x * (1 - a.z) * (at(0, 0, 1) - at(0, 1, 1)) +
              (1 - a.x) * (1 - a.z) * (at(1, 0, 1) - at(1, 1, 1));
  if (f.z != 0.0)
    force.z = a.x * a.y * (at(0, 0, 0) - at(0, 0, 1)) + (1 - a.x) * a.y * (at(1, 0, 0) - at(1, 0, 1)) +
              a.x * (1 - a.y) * (at(0, 1, 0) - at(0, 1, 1)) +
              (1 - a.x) * (1 - a.y) * (at(1, 1, 0) - at(1, 1, 1));
  return force;
}

double densityEnergy(const Grid& d) {
  double sum = 0.0;
  for (float v : d.values) sum += double(v) * double(v);
  return 0.5 * sum;
}

}  // namespace hairgen
