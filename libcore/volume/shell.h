// Petrovic, Henne and Anderson, Volumetric Methods for Simulation and Rendering of Hair, Pixar Technical Memo
// 06-08 (2006), §4.1: the hair's shell and its shading normals. The isosurface of a chosen density of the
// splat is the shell; the signed distance S to it (|∇S| = 1, S = 0 on the shell, negative inside) has
// gradient N = ∇S, a shading normal that makes the hair shade like one body, with terminators that line up
// with the head's.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "libcore/model/strands.h"
#include "libcore/volume/grid.h"

namespace hairgen {

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
