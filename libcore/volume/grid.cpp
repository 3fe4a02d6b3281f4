#include "libcore/volume/grid.h"

#include <algorithm>
#include <cmath>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include "libcore/util/error.h"

namespace hairgen {

using grid_detail::trilinear;

template <class T>
typename GridOf<T>::Sample GridOf<T>::sample(const glm::dvec3& p) const {
  if (size.x < 2 || size.y < 2 || size.z < 2)
    return trilinear<Sample>(*this, p, [&](int i, int j, int k) { return Sample(at(i, j, k)); });
  // trilinear's operations in its order, with the cell found once: g < size − 1, so the cell's far
  // corners are inside the grid and need no clamp (the min only matters past 2²⁴ nodes an axis, where
  // size − 1 − 1e-9 rounds to size − 1).
  const glm::dvec3 g = glm::clamp((p - origin) / voxel, glm::dvec3(0.0), glm::dvec3(size - 1) - 1e-9);
  const glm::ivec3 c = glm::min(glm::ivec3(glm::floor(g)), size - 2);
  const glm::dvec3 f = g - glm::dvec3(c);
  const size_t row = size_t(size.x), slab = row * size_t(size.y);
  const T* corner = &values[index(c.x, c.y, c.z)];
  Sample out(0.0);
  for (int dz = 0; dz < 2; ++dz)
    for (int dy = 0; dy < 2; ++dy) {
      const T* at = corner + size_t(dz) * slab + size_t(dy) * row;
      const double wy = dy ? f.y : 1 - f.y, wz = dz ? f.z : 1 - f.z;
      out += ((1 - f.x) * wy * wz) * Sample(at[0]);
      out += (f.x * wy * wz) * Sample(at[1]);
    }
  return out;
}

Bounds boundsInParallel(std::span<const glm::vec3> points) {
  if (points.empty()) return {};
  const Bounds none{glm::vec3(std::numeric_limits<float>::max()),
                    glm::vec3(std::numeric_limits<float>::lowest())};
  // parallel_reduce joins the boxes of neighbouring ranges left to right, and glm::min and max keep
  // the left of two equal values (+0 and −0): the serial loop's choices.
  return tbb::parallel_reduce(
      tbb::blocked_range<size_t>(0, points.size(), 65536), none,
      [&](const tbb::blocked_range<size_t>& r, Bounds b) {
        for (size_t i = r.begin(); i < r.end(); ++i) {
          b.min = glm::min(b.min, points[i]);
          b.max = glm::max(b.max, points[i]);
        }
        return b;
      },
      [](const Bounds& a, const Bounds& b) {
        return Bounds{glm::min(a.min, b.min), glm::max(a.max, b.max)};
      });
}

template <class T>
GridOf<T> gridAround(std::span<const glm::vec3> points, double voxel, int padding) {
  if (points.empty()) throw InputError("the coupe has no points to build a volume from");
  const Bounds box = boundsInParallel(points);
  const glm::dvec3 lo(box.min), hi(box.max);
  GridOf<T> g;
  g.voxel = voxel;
  g.origin = lo - double(padding) * voxel;
  glm::dvec3 cells = glm::ceil((hi - lo) / voxel) + 1.0 + 2.0 * padding;
  if (cells.x * cells.y * cells.z > 4.0e8) {
    const glm::dvec3 span = hi - lo;
    char text[160];
    std::snprintf(text, sizeof text,
                  "the hair spans %.3g x %.3g x %.3g, which at VoxelSize %.3g is %.3g voxels (4e8 at most)",
                  span.x, span.y, span.z, voxel, cells.x * cells.y * cells.z);
    throw InputError(std::string(text) + "; raise Render.VoxelSize, or check the cache is in metres");
  }
  g.size = glm::ivec3(cells);
  g.values.assign(size_t(g.size.x) * g.size.y * g.size.z, T(0.0f));
  return g;
}

template <class T>
void smoothInPlace(GridOf<T>& g) {
  // Separable [1 2 1]/4 along x, y and z, edges clamped (an edge node keeps 3/4 of itself and gives
  // its neighbour 1/4, as that neighbour gives it: the matrix stays symmetric). Line by line through a
  // copy of the line; lines are independent, so any thread count gives the same bits.
  using Scalar = std::conditional_t<std::is_same_v<T, float>, float, double>;
  const Scalar quarter = Scalar(0.25), half = Scalar(0.5);
  const glm::ivec3 n = g.size;
  for (int axis = 0; axis < 3; ++axis) {
    const size_t stride = axis == 0 ? 1 : axis == 1 ? size_t(n.x) : size_t(n.x) * size_t(n.y);
    const int length = n[axis], u = (axis + 1) % 3, w = (axis + 2) % 3;
    tbb::parallel_for(0, n[w], [&](int cw) {
      std::vector<T> line(static_cast<size_t>(length));
      for (int cu = 0; cu < n[u]; ++cu) {
        glm::ivec3 c(0);
        c[u] = cu;
        c[w] = cw;
        T* first = &g.values[g.index(c.x, c.y, c.z)];
        for (int t = 0; t < length; ++t) line[size_t(t)] = first[size_t(t) * stride];
        for (int t = 0; t < length; ++t)
          first[size_t(t) * stride] = quarter * line[size_t(std::max(t - 1, 0))] + half * line[size_t(t)] +
                                      quarter * line[size_t(std::min(t + 1, length - 1))];
      }
    });
  }
}

template <class T>
GridOf<T> smoothed(const GridOf<T>& g) {
  GridOf<T> out = g;
  smoothInPlace(out);
  return out;
}

template struct GridOf<float>;
template struct GridOf<glm::dvec4>;
template GridOf<float> gridAround<float>(std::span<const glm::vec3>, double, int);
template GridOf<glm::dvec4> gridAround<glm::dvec4>(std::span<const glm::vec3>, double, int);
template void smoothInPlace<float>(GridOf<float>&);
template void smoothInPlace<glm::dvec4>(GridOf<glm::dvec4>&);
template GridOf<float> smoothed<float>(const GridOf<float>&);
template GridOf<glm::dvec4> smoothed<glm::dvec4>(const GridOf<glm::dvec4>&);

}  // namespace hairgen
