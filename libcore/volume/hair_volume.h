// Petrovic, Henne and Anderson 2005 (Pixar), §3-4: hair as a volume. Strand points are splatted onto a
// density grid with a tent kernel; the isosurface of a chosen density is the hair's shell; the signed
// distance S to it (|∇S| = 1, S = 0 on the shell, negative inside) has gradient N = ∇S, a shading
// normal that makes the hair shade like one body, with terminators that line up with the head's.
#pragma once

#include <cstdint>
#include <span>
#include <type_traits>
#include <utility>
#include <vector>

#include <glm/glm.hpp>

#include "libcore/model/mesh.h"
#include "libcore/model/strands.h"

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

// One pass of a separable binomial [1 2 1]/4 filter, edges clamped. As a matrix it is symmetric,
// non-negative and doubly stochastic (every row and column sums to 1): it keeps the total, and a
// weighted average stays a weighted average.
template <class T>
GridOf<T> smoothed(const GridOf<T>& grid);
// The same filter on `grid` itself (no second grid; the same bits as smoothed()).
template <class T>
void smoothInPlace(GridOf<T>& grid);

// Petrovic et al. §5.2: the force on a point at `p` from the density difference `difference` = D_s −
// D_t of the memo's (3), E = ½ Σ (D_s − D_t)²: −∂E/∂p in grid units (p measured in voxels), the memo's
// F_x, F_y, F_z (points per node). Along an axis where p sits exactly on a grid line the derivative is
// taken as 0, as the memo does. Zero outside the grid.
glm::dvec3 densityForce(const Grid& difference, const glm::dvec3& p);

// E = ½ Σ d² over the nodes of `difference`, summed in node order.
double densityEnergy(const Grid& difference);

// The signed distance to the isosurface density = `iso` (negative inside): the nodes next to the
// shell start from its sub-voxel crossings, fast sweeping carries nearest points to the rest of the
// grid, and each node slides its point along the shell to the true nearest one.
// With `exactAt` (one flag per node), only the flagged nodes slide; the others keep the sweep's
// distance, a shell point's, which is at most about a voxel too long.
Grid signedDistance(const Grid& density, double iso, const std::vector<uint8_t>* exactAt = nullptr);

// The nodes of `grid` whose values volumeNormals reads for these points: the corners of each point's
// cell, and their neighbours along the axes (nodeGradients' central differences). One flag per node.
std::vector<uint8_t> nodesNormalsRead(const Grid& grid, std::span<const glm::vec3> points);

// The density at a typical hair point: Σd²/Σd over the nodes, the mean density weighted by how much
// hair sits there. Scale-free shell densities are fractions of it.
double typicalDensity(const Grid& density);

// What `hairgen shade` builds: the splat, and the signed distance to the shell at
// `shellFraction`·typicalDensity of the splat after one smoothing pass (the shell of a splat of
// strands is bumpy at the scale of the strand spacing; the pass keeps the mass where it is).
struct HairVolume {
  Grid density;   // strand points per voxel, as splatted
  Grid distance;  // metres, negative inside the shell
  double iso = 0.0;
  bool distanceEverywhere = true;  // false: `distance` is exact only where the normals read it
};
// `distanceEverywhere` false: the distance is exact only at the nodes the strands' normals read
// (nodesNormalsRead), so volumeNormals gives the same bits for a fraction of the work; true for a
// volume that is written out (`shade --vdb`).
HairVolume buildVolume(const Strands& strands, double voxel, int padding, double shellFraction,
                       bool distanceEverywhere = true);

// Shading normals ∇S/|∇S| at every strand vertex.
std::vector<glm::vec3> volumeNormals(const Grid& distance, const Strands& strands);
// The same written over `normals`, resized to the vertex count (its storage kept when it has room).
void volumeNormals(const Grid& distance, const Strands& strands, std::vector<glm::vec3>& normals);

}  // namespace hairgen
