// The hair volume as OpenVDB float grids, for Houdini, Blender and anything else that opens .vdb.
#pragma once

#include <filesystem>

#include "libcore/volume/shell.h"

namespace hairgen {

// Writes two FloatGrids in world metres (voxel size VoxelSize, node (i, j, k) at origin + h·(i, j, k)):
//   "density" — strand points per voxel as splatted, class fog volume, background 0;
//   "sdf"     — signed distance to the hair shell in metres, negative inside, class level set, with
//               every node of the grid active (not only a narrow band), background the largest distance.
// File metadata: "producer", "shell_density" (the iso value). Atomic; IoError when it cannot be written.
void writeVdb(const std::filesystem::path& path, const HairVolume& volume);

}  // namespace hairgen
