// The hair volume as OpenVDB float grids by OpenVDB's conventions, for Houdini, Blender and anything
// else that opens .vdb.
#pragma once

#include <filesystem>

#include "libcore/volume/shell.h"

namespace hairgen {

// The level set's half width, in voxels: OpenVDB's LEVEL_SET_HALF_WIDTH, what its tools expect.
inline constexpr double kVdbHalfWidth = 3.0;

// Writes two FloatGrids in world metres (voxel size VoxelSize, node (i, j, k) at origin + h·(i, j, k)):
//   "density" — class fog volume: points per voxel as splatted over the grid's largest, so in [0, 1];
//               background 0, zero nodes inactive. Grid metadata: "hairgen_points_per_voxel_at_1"
//               (the scale: points per voxel = value × it) and "hairgen_shell_density" (the shell's
//               density on the same [0, 1] scale).
//   "sdf"     — class level set: signed distance to the hair shell in metres, negative inside, active
//               in a narrow band of kVdbHalfWidth voxels each side, background kVdbHalfWidth voxels;
//               inactive values are ±background (outside, inside). Smoothed by one Gaussian pass of
//               OpenVDB's level-set filter, which takes out wisps and crevices thinner than a voxel
//               (a narrow band cannot hold them) and moves the shell by less than a voxel elsewhere.
// Both pass OpenVDB's own checks (tools::checkFogVolume, tools::checkLevelSet). File metadata:
// "producer", "shell_density" (the iso value, points per voxel). Atomic; IoError when it cannot be
// written.
void writeVdb(const std::filesystem::path& path, const HairVolume& volume);

}  // namespace hairgen
