#include "libcore/io/vdb_io.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>
#include <openvdb/tools/LevelSetFilter.h>
#include <openvdb/tools/Prune.h>
#include <openvdb/tools/SignedFloodFill.h>

#include "libcore/util/error.h"
#include "libcore/util/file_util.h"

namespace hairgen {
namespace {

openvdb::FloatGrid::Ptr emptyGrid(const Grid& grid, float background) {
  openvdb::FloatGrid::Ptr out = openvdb::FloatGrid::create(background);
  openvdb::math::Transform::Ptr xform = openvdb::math::Transform::createLinearTransform(grid.voxel);
  xform->postTranslate(openvdb::Vec3d(grid.origin.x, grid.origin.y, grid.origin.z));
  out->setTransform(xform);
  return out;
}

// The density as a fog volume: each node's points per voxel over the grid's largest, so values lie in
// [0, 1]; zero nodes stay inactive (the background).
openvdb::FloatGrid::Ptr fogVolume(const Grid& density, double iso) {
  float largest = 0.0f;
  for (float v : density.values) largest = std::max(largest, v);
  openvdb::FloatGrid::Ptr out = emptyGrid(density, 0.0f);
  openvdb::FloatGrid::Accessor access = out->getAccessor();
  if (largest > 0.0f)
    for (int k = 0; k < density.size.z; ++k)
      for (int j = 0; j < density.size.y; ++j)
        for (int i = 0; i < density.size.x; ++i)
          if (const float v = density.at(i, j, k); v > 0.0f)
            access.setValue(openvdb::Coord(i, j, k), std::min(v / largest, 1.0f));
  out->setName("density");
  out->setGridClass(openvdb::GRID_FOG_VOLUME);
  out->insertMeta("hairgen_points_per_voxel_at_1", openvdb::DoubleMetadata(largest));
  out->insertMeta("hairgen_shell_density", openvdb::DoubleMetadata(largest > 0.0f ? iso / largest : 0.0));
  return out;
}

// The signed distance as a narrow-band level set: nodes within kVdbHalfWidth voxels of the shell
// active, the rest inactive at ±background (outside, inside) by OpenVDB's signed flood fill; then one
// Gaussian pass of OpenVDB's level-set filter (width one voxel, renormalised). A splatted shell has
// wisps and crevices thinner than a voxel, which no narrow band can hold with |grad| = 1 at its zero
// crossings (the coupe3 test volume: 538 such voxels); the pass smooths them away and moves the rest
// of the shell by a fraction of a voxel.
openvdb::FloatGrid::Ptr levelSet(const Grid& distance) {
  const float background = float(kVdbHalfWidth * distance.voxel);
  openvdb::FloatGrid::Ptr out = emptyGrid(distance, background);
  openvdb::FloatGrid::Accessor access = out->getAccessor();
  for (int k = 0; k < distance.size.z; ++k)
    for (int j = 0; j < distance.size.y; ++j)
      for (int i = 0; i < distance.size.x; ++i)
        if (const float v = distance.at(i, j, k); std::abs(v) < background)
          access.setValue(openvdb::Coord(i, j, k), v);
  openvdb::tools::signedFloodFill(out->tree());
  out->setGridClass(openvdb::GRID_LEVEL_SET);
  openvdb::tools::LevelSetFilter<openvdb::FloatGrid> filter(*out);
  filter.gaussian(1);
  openvdb::tools::pruneLevelSet(out->tree());
  out->setName("sdf");
  return out;
}

}  // namespace

void writeVdb(const std::filesystem::path& path, const HairVolume& volume) {
  if (!volume.distanceEverywhere)  // a caller's slip, not the user's: the file would lie away from the hair
    throw std::logic_error(
        "writing " + path.string() +
        ": the volume's distance was computed only near the hair (ShadeOptions::distanceEverywhere)");
  openvdb::initialize();
  openvdb::GridPtrVec grids{fogVolume(volume.density, volume.iso), levelSet(volume.distance)};
  openvdb::MetaMap meta;
  meta.insertMeta("producer", openvdb::StringMetadata("hairgen " HAIRGEN_VERSION));
  meta.insertMeta("shell_density", openvdb::DoubleMetadata(volume.iso));
  writeThroughTemporary(path, [&](const std::filesystem::path& temporary) {
    try {
      openvdb::io::File file(temporary.string());
      file.write(grids, meta);
      file.close();
    } catch (const openvdb::Exception& e) {
      throw IoError(path.string() + ": cannot write the volume: " + e.what());
    }
  });
}

}  // namespace hairgen
