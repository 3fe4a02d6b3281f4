// The regular grid every volume algorithm of Petrovic, Henne and Anderson, Volumetric Methods for Simulation
// and Rendering of Hair, Pixar Technical Memo 06-08 (2006) works on: values at nodes, their trilinear sample
// (the tent weights of the memo's eq. 1), and the binomial smoothing the shell (§4.1) and velocity smoothing
// (§5.1) both use.
#pragma once

#include <algorithm>
#include <cstdint>
#include <span>
#include <type_traits>
#include <utility>
#include <vector>

#include <glm/glm.hpp>

#include "libcore/model/mesh.h"

namespace hairgen {

// Values at the nodes of a regular grid: node (i, j, k) sits at origin + h·(i, j, k). The density is a
// grid of floats (Grid); dynamics (libcore/physics/spring_dynamics.h) keeps masses and momenta on the
// same grids in doubles.
template <class T>
struct GridOf {
  // What sample() returns: doubles for a float grid, T itself otherwise.
  using Sample = std::conditional_t<std::is_same_v<T, float>, double, T>;

  glm::dvec3 origin{0.0};
  double voxel = 1.0;
  glm::ivec3 size{0};
  std::vector<T> values;
  size_t index(int i, int j, int k) const { return (size_t(k) * size.y + j) * size.x + i; }
  const T& at(int i, int j, int k) const { return values[index(i, j, k)]; }
  // Trilinear value at a world point (clamped to the grid): the tent weights of the paper's (1), the
  // same weights splat() and splatValues() give the point.
  Sample sample(const glm::dvec3& p) const;
};
using Grid = GridOf<float>;

// bounds(points) from every core, for the millions of points of a coupe: a minimum or maximum does
// not round, and the threads' boxes join in the points' order, so it is the same box to the bit.
Bounds boundsInParallel(std::span<const glm::vec3> points);

// A grid around `points` with `padding` empty nodes on every side, all values zero. Throws InputError
// beyond 4e8 nodes.
template <class T = float>
GridOf<T> gridAround(std::span<const glm::vec3> points, double voxel, int padding);

// One pass of a separable binomial [1 2 1]/4 filter, edges clamped. As a matrix it is symmetric,
// non-negative and doubly stochastic (every row and column sums to 1): it keeps the total, and a
// weighted average stays a weighted average.
template <class T>
GridOf<T> smoothed(const GridOf<T>& grid);
// The same filter on `grid` itself (no second grid; the same bits as smoothed()).
template <class T>
void smoothInPlace(GridOf<T>& grid);

namespace grid_detail {

// Calls corner(w, i, j, k) for the 8 nodes around p (clamped to the grid) with their trilinear weights,
// z outermost and x innermost.
template <class G, class Corner>
void forEachCorner(const G& grid, const glm::dvec3& p, Corner corner) {
  glm::dvec3 g =
      glm::clamp((p - grid.origin) / grid.voxel, glm::dvec3(0.0), glm::dvec3(grid.size - 1) - 1e-9);
  glm::ivec3 c = glm::ivec3(glm::floor(g));
  glm::dvec3 f = g - glm::dvec3(c);
  for (int dz = 0; dz < 2; ++dz)
    for (int dy = 0; dy < 2; ++dy)
      for (int dx = 0; dx < 2; ++dx) {
        double w = (dx ? f.x : 1 - f.x) * (dy ? f.y : 1 - f.y) * (dz ? f.z : 1 - f.z);
        corner(w, std::min(c.x + dx, grid.size.x - 1), std::min(c.y + dy, grid.size.y - 1),
               std::min(c.z + dz, grid.size.z - 1));
      }
}

// Σ over the 8 nodes around p of their trilinear weight times value(i, j, k) (p clamped to the grid).
template <class T, class G, class Value>
T trilinear(const G& grid, const glm::dvec3& p, Value value) {
  T out(0.0);
  forEachCorner(grid, p, [&](double w, int i, int j, int k) { out += w * value(i, j, k); });
  return out;
}

}  // namespace grid_detail

}  // namespace hairgen
