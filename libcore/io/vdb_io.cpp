#include "libcore/io/vdb_io.h"

#include <algorithm>
#include <stdexcept>

#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>

#include "libcore/util/error.h"
#include "libcore/util/file_util.h"

namespace hairgen {
namespace {

openvdb::FloatGrid::Ptr toVdb(const Grid& grid, float background, bool everyNode) {
  openvdb::FloatGrid::Ptr out = openvdb::FloatGrid::create(background);
  openvdb::math::Transform::Ptr xform = openvdb::math::Transform::createLinearTransform(grid.voxel);
  xform->postTranslate(openvdb::Vec3d(grid.origin.x, grid.origin.y, grid.origin.z));
  out->setTransform(xform);
  openvdb::FloatGrid::Accessor access = out->getAccessor();
  for (int k = 0; k < grid.size.z; ++k)
    for (int j = 0; j < grid.size.y; ++j)
      for (int i = 0; i < grid.size.x; ++i) {
        const float v = grid.at(i, j, k);
        if (everyNode || v != background) access.setValue(openvdb::Coord(i, j, k), v);
      }
  return out;
}

}  // namespace

void writeVdb(const std::filesystem::path& path, const HairVolume& volume) {
  if (!volume.distanceEverywhere)  // a caller's slip, not the user's: the file would lie away from the hair
    throw std::logic_error(
        "writing " + path.string() +
        ": the volume's distance was computed only near the hair (ShadeOptions::distanceEverywhere)");
  openvdb::initialize();
  openvdb::FloatGrid::Ptr density = toVdb(volume.density, 0.0f, false);
  density->setName("density");
  density->setGridClass(openvdb::GRID_FOG_VOLUME);
  float largest = 0.0f;
  for (float v : volume.distance.values) largest = std::max(largest, std::abs(v));
  openvdb::FloatGrid::Ptr sdf = toVdb(volume.distance, largest, true);
  sdf->setName("sdf");
  sdf->setGridClass(openvdb::GRID_LEVEL_SET);
  openvdb::GridPtrVec grids{density, sdf};
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
