#include "libcore/hair_volume.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "libcore/error.h"
#include "libcore/mesh.h"

namespace hairgen {

namespace {

// Σ over the 8 nodes around p of their trilinear weight times value(i, j, k) (p clamped to the grid).
template <class T, class Value>
T trilinear(const Grid& grid, const glm::dvec3& p, Value value) {
  glm::dvec3 g = glm::clamp((p - grid.origin) / grid.voxel, glm::dvec3(0.0), glm::dvec3(grid.size - 1) - 1e-9);
  glm::ivec3 c = glm::ivec3(glm::floor(g));
  glm::dvec3 f = g - glm::dvec3(c);
  T out(0.0);
  for (int dz = 0; dz < 2; ++dz)
    for (int dy = 0; dy < 2; ++dy)
      for (int dx = 0; dx < 2; ++dx) {
        double w = (dx ? f.x : 1 - f.x) * (dy ? f.y : 1 - f.y) * (dz ? f.z : 1 - f.z);
        out += w * value(std::min(c.x + dx, grid.size.x - 1), std::min(c.y + dy, grid.size.y - 1),
                         std::min(c.z + dz, grid.size.z - 1));
      }
  return out;
}

}  // namespace

double Grid::sample(const glm::dvec3& p) const {
  return trilinear<double>(*this, p, [&](int i, int j, int k) { return double(at(i, j, k)); });
}

glm::dvec3 Grid::gradient(const glm::dvec3& p) const {
  // The trilinear interpolant of the nodes' central differences.
  auto v = [&](int a, int b, int d) {
    return double(at(std::clamp(a, 0, size.x - 1), std::clamp(b, 0, size.y - 1), std::clamp(d, 0, size.z - 1)));
  };
  return trilinear<glm::dvec3>(*this, p, [&](int i, int j, int k) {
    return glm::dvec3(v(i + 1, j, k) - v(i - 1, j, k), v(i, j + 1, k) - v(i, j - 1, k), v(i, j, k + 1) - v(i, j, k - 1)) /
           (2.0 * voxel);
  });
}

Grid gridAround(const std::vector<glm::vec3>& points, double voxel, int padding) {
  if (points.empty()) throw InputError("the coupe has no points to build a volume from");
  const Bounds box = bounds(points);
  const glm::dvec3 lo(box.min), hi(box.max);
  Grid g;
  g.voxel = voxel;
  g.origin = lo - double(padding) * voxel;
  glm::dvec3 cells = glm::ceil((hi - lo) / voxel) + 1.0 + 2.0 * padding;
  if (cells.x * cells.y * cells.z > 4.0e8)
    throw InputError("the volume would need " + std::to_string(int64_t(cells.x * cells.y * cells.z)) +
                     " voxels; raise VoxelSize");
  g.size = glm::ivec3(cells);
  g.values.assign(size_t(g.size.x) * g.size.y * g.size.z, 0.0f);
  return g;
}

void splat(Grid& d, const std::vector<glm::vec3>& points) {
  // One thread, in point order: the sums are the same bits on every run.
  for (const glm::vec3& point : points) {
    glm::dvec3 g = (glm::dvec3(point) - d.origin) / d.voxel;
    glm::ivec3 c = glm::ivec3(glm::floor(g));
    glm::dvec3 f = g - glm::dvec3(c);
    for (int dz = 0; dz < 2; ++dz)
      for (int dy = 0; dy < 2; ++dy)
        for (int dx = 0; dx < 2; ++dx) {
          glm::ivec3 n = c + glm::ivec3(dx, dy, dz);
          if (glm::any(glm::lessThan(n, glm::ivec3(0))) || glm::any(glm::greaterThanEqual(n, d.size))) continue;
          d.values[d.index(n.x, n.y, n.z)] +=
              static_cast<float>((dx ? f.x : 1 - f.x) * (dy ? f.y : 1 - f.y) * (dz ? f.z : 1 - f.z));
        }
  }
}

Grid smoothed(const Grid& g) {
  // Separable [1 2 1]/4 along x, y and z, edges clamped.
  Grid out = g;
  const glm::ivec3 n = g.size;
  for (int axis = 0; axis < 3; ++axis) {
    Grid in = out;
    for (int k = 0; k < n.z; ++k)
      for (int j = 0; j < n.y; ++j)
        for (int i = 0; i < n.x; ++i) {
          glm::ivec3 c(i, j, k), a = c, b = c;
          a[axis] = std::max(c[axis] - 1, 0);
          b[axis] = std::min(c[axis] + 1, n[axis] - 1);
          out.values[out.index(i, j, k)] =
              0.25f * in.at(a.x, a.y, a.z) + 0.5f * in.at(i, j, k) + 0.25f * in.at(b.x, b.y, b.z);
        }
  }
  return out;
}

Grid signedDistance(const Grid& rawDensity, double iso) {
  // The shell of a splat of strands is bumpy at the scale of the strand spacing; one binomial pass
  // leaves the mass where it is and takes the bumps out of the normals.
  const Grid density = smoothed(rawDensity);
  Grid s = density;
  const glm::ivec3 n = density.size;
  const double h = density.voxel, inf = std::numeric_limits<double>::infinity();
  std::vector<double> dist(s.values.size(), inf);
  std::vector<char> inside(s.values.size());
  for (size_t i = 0; i < s.values.size(); ++i) inside[i] = density.values[i] > iso;
  // Nodes next to the shell (an edge to a neighbour crosses it): the distance |φ|/|∇φ| of the linear
  // approximation of φ = density − iso, from central differences; never more than a voxel.
  auto phi = [&](int i, int j, int k) {
    return double(density.at(std::clamp(i, 0, n.x - 1), std::clamp(j, 0, n.y - 1), std::clamp(k, 0, n.z - 1))) - iso;
  };
  const glm::ivec3 steps[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  for (int k = 0; k < n.z; ++k)
    for (int j = 0; j < n.y; ++j)
      for (int i = 0; i < n.x; ++i) {
        const size_t id = density.index(i, j, k);
        bool crossing = false;
        for (const glm::ivec3& st : steps) {
          glm::ivec3 b(i + st.x, j + st.y, k + st.z);
          if (glm::all(glm::greaterThanEqual(b, glm::ivec3(0))) && glm::all(glm::lessThan(b, n)))
            crossing = crossing || inside[density.index(b.x, b.y, b.z)] != inside[id];
        }
        if (!crossing) continue;
        glm::dvec3 grad((phi(i + 1, j, k) - phi(i - 1, j, k)) / (2 * h), (phi(i, j + 1, k) - phi(i, j - 1, k)) / (2 * h),
                        (phi(i, j, k + 1) - phi(i, j, k - 1)) / (2 * h));
        double g = glm::length(grad);
        dist[id] = g > 0.0 ? std::min(std::abs(phi(i, j, k)) / g, h) : h;
      }
  // Fast sweeping (Zhao 2005): Godunov's upwind update of |∇S| = 1 in 8 sweep orders, twice.
  auto update = [&](int i, int j, int k) {
    size_t id = s.index(i, j, k);
    auto nb = [&](int a, int b, int c) { return dist[s.index(a, b, c)]; };
    double a = std::min(i > 0 ? nb(i - 1, j, k) : inf, i + 1 < n.x ? nb(i + 1, j, k) : inf);
    double b = std::min(j > 0 ? nb(i, j - 1, k) : inf, j + 1 < n.y ? nb(i, j + 1, k) : inf);
    double c = std::min(k > 0 ? nb(i, j, k - 1) : inf, k + 1 < n.z ? nb(i, j, k + 1) : inf);
    double v[3] = {a, b, c};
    std::sort(v, v + 3);
    if (v[0] == inf) return;
    double x = v[0] + h;
    if (x > v[1]) {
      double sum = v[0] + v[1], disc = 2.0 * h * h - (v[0] - v[1]) * (v[0] - v[1]);
      x = 0.5 * (sum + std::sqrt(std::max(disc, 0.0)));
      if (x > v[2]) {
        double s3 = v[0] + v[1] + v[2];
        double q = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
        double d3 = s3 * s3 - 3.0 * (q - h * h);
        x = (s3 + std::sqrt(std::max(d3, 0.0))) / 3.0;
      }
    }
    if (x < dist[id]) dist[id] = x;
  };
  for (int pass = 0; pass < 2; ++pass)
    for (int order = 0; order < 8; ++order) {
      const bool fx = order & 1, fy = order & 2, fz = order & 4;
      for (int kk = 0; kk < n.z; ++kk)
        for (int jj = 0; jj < n.y; ++jj)
          for (int ii = 0; ii < n.x; ++ii)
            update(fx ? n.x - 1 - ii : ii, fy ? n.y - 1 - jj : jj, fz ? n.z - 1 - kk : kk);
    }
  for (size_t i = 0; i < s.values.size(); ++i) {
    double d = std::isfinite(dist[i]) ? dist[i] : h * (n.x + n.y + n.z);
    s.values[i] = static_cast<float>(inside[i] ? -d : d);
  }
  return s;
}

std::vector<glm::vec3> volumeNormals(const Grid& distance, const Strands& strands) {
  std::vector<glm::vec3> normals(strands.pointCount());
  for (size_t i = 0; i < strands.pointCount(); ++i) {
    glm::dvec3 g = distance.gradient(glm::dvec3(strands.points[i]));
    double len = glm::length(g);
    normals[i] = len > 1e-12 ? glm::vec3(g / len) : glm::vec3(0, 1, 0);
  }
  return normals;
}

namespace {

// The minimal rotation taking unit a to unit b, applied to v.
glm::dvec3 transport(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& v) {
  glm::dvec3 axis = glm::cross(a, b);
  double s = glm::length(axis), c = glm::dot(a, b);
  if (s < 1e-14) return c > 0.0 ? v : -v;
  axis /= s;
  return v * c + glm::cross(axis, v) * s + axis * glm::dot(axis, v) * (1.0 - c);
}

}  // namespace

std::vector<glm::vec3> transportFrames(const Strands& s) {
  const std::vector<glm::vec3> tangents = tangentsOf(s);
  glm::dvec3 centroid(0.0);
  for (size_t i = 0; i < s.strandCount(); ++i) centroid += glm::dvec3(s.points[s.firstPoint[i]]);
  centroid /= double(std::max<size_t>(s.strandCount(), 1));
  std::vector<glm::vec3> u(s.pointCount());
  for (size_t i = 0; i < s.strandCount(); ++i) {
    const uint32_t first = s.firstPoint[i], last = s.firstPoint[i + 1];
    if (first == last) continue;
    glm::dvec3 t = glm::normalize(glm::dvec3(tangents[first]));
    glm::dvec3 ref = centroid - glm::dvec3(s.points[first]);
    glm::dvec3 frame = ref - glm::dot(ref, t) * t;
    if (glm::length(frame) < 1e-9) frame = glm::cross(t, std::abs(t.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0));
    frame = glm::normalize(frame);
    u[first] = glm::vec3(frame);
    for (uint32_t p = first + 1; p < last; ++p) {
      glm::dvec3 next = glm::normalize(glm::dvec3(tangents[p]));
      frame = glm::normalize(transport(t, next, frame));
      frame = glm::normalize(frame - glm::dot(frame, next) * next);
      t = next;
      u[p] = glm::vec3(frame);
    }
  }
  return u;
}

std::vector<glm::vec3> reposeNormals(const Strands& rest, const Strands& deformed) {
  if (rest.strandCount() != deformed.strandCount() || rest.firstPoint != deformed.firstPoint)
    throw InputError("the rest coupe and the coupe to re-pose differ in strands or vertex counts");
  if (rest.normals.empty()) throw InputError("the rest coupe has no normals; run hairgen shade on it first");
  const std::vector<glm::vec3> tr = tangentsOf(rest), td = tangentsOf(deformed);
  const std::vector<glm::vec3> ur = transportFrames(rest), ud = transportFrames(deformed);
  std::vector<glm::vec3> out(deformed.pointCount());
  for (size_t p = 0; p < out.size(); ++p) {
    glm::dvec3 t(glm::normalize(tr[p])), u(ur[p]), v = glm::cross(t, u);
    glm::dvec3 n(rest.normals[p]);
    glm::dvec3 local(glm::dot(n, t), glm::dot(n, u), glm::dot(n, v));
    glm::dvec3 t2(glm::normalize(td[p])), u2(ud[p]), v2 = glm::cross(t2, u2);
    out[p] = glm::vec3(glm::normalize(local.x * t2 + local.y * u2 + local.z * v2));
  }
  return out;
}

}  // namespace hairgen
