// Petrovic, Henne and Anderson 2005 (Pixar), §3-4: hair as a volume. Strand points are splatted onto a
// density grid with a tent kernel; the isosurface of a chosen density is the hair's shell; the signed
// distance S to it (|∇S| = 1, S = 0 on the shell, negative inside) has gradient N = ∇S, a shading
// normal that makes the hair shade like one body, with terminators that line up with the head's.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "libcore/model/strands.h"

namespace hairgen {

// Values at the nodes of a regular grid: node (i, j, k) sits at origin + h·(i, j, k).
struct Grid {
  glm::dvec3 origin{0.0};
  double voxel = 1.0;
  glm::ivec3 size{0};
  std::vector<float> values;
  size_t index(int i, int j, int k) const { return (size_t(k) * size.y + j) * size.x + i; }
  float at(int i, int j, int k) const { return values[index(i, j, k)]; }
  // Trilinear value at a world point (clamped to the grid).
  double sample(const glm::dvec3& p) const;
};

// A grid around `points` with `padding` empty nodes on every side.
Grid gridAround(const std::vector<glm::vec3>& points, double voxel, int padding);

// Splats every point with the tent (trilinear) kernel of the paper's (1): each point adds weights
// summing to exactly 1 to the 8 nodes around it, so the grid sums to the number of points inside it.
// Parallel, and the same bits whatever the thread count.
void splat(Grid& density, const std::vector<glm::vec3>& points);

// One pass of a separable binomial [1 2 1]/4 filter (mass-preserving away from the edges).
Grid smoothed(const Grid& grid);

// The signed distance to the isosurface density = `iso` (negative inside): the nodes next to the
// shell start from its sub-voxel crossings, fast sweeping carries nearest points to the rest of the
// grid, and each node slides its point along the shell to the true nearest one.
Grid signedDistance(const Grid& density, double iso);

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
};
HairVolume buildVolume(const Strands& strands, double voxel, int padding, double shellFraction);

// Shading normals ∇S/|∇S| at every strand vertex.
std::vector<glm::vec3> volumeNormals(const Grid& distance, const Strands& strands);

}  // namespace hairgen
