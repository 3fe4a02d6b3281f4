// Petrovic, Henne and Anderson, Volumetric Methods for Simulation and Rendering of Hair, Pixar Technical Memo
// 06-08 (2006), eq. 1: strand points splatted onto a grid with the tent (trilinear) kernel, the density grid
// of §4 and the momentum grids of §5.1.
#pragma once

#include <span>
#include <utility>
#include <vector>

#include <glm/glm.hpp>

#include "libcore/volume/grid.h"

namespace hairgen {

// Splats every point with the tent (trilinear) kernel of the paper's (1): each point adds weights
// summing to exactly 1 to the 8 nodes around it, so the grid sums to the number of points inside it.
// Parallel, and the same bits whatever the thread count. Each thread sums into a grid of its own, as
// many as fit in kSplatCopiesBytes (at least one): a many-core machine with a fine grid runs the
// splat on fewer threads rather than holding a grid per core.
constexpr double kSplatCopiesBytes = 256.0 * 1024 * 1024;
void splat(Grid& density, std::span<const glm::vec3> points);

// Adds values[i] times point i's tent weights to the 8 nodes around it (the outer corners of a point
// at the grid's edge fall away). Sums in a fixed order, whatever the thread count: points by z-slab of
// the grid, even slabs then odd ones (the two never share a node), each slab's points in index order;
// so the grid holds the same bits for 1 thread or 64. `values` has one entry per point. `sorted`: the
// points and values in that order, the caller's memory (kept between calls, it is reused).
template <class T>
using SplatEntries = std::vector<std::pair<glm::dvec3, T>>;
template <class T>
void splatValues(GridOf<T>& grid, const std::vector<glm::dvec3>& points, const std::vector<T>& values,
                 SplatEntries<T>& sorted);

}  // namespace hairgen
