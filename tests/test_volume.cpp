// The volumetric hair model: splatting, the hair shell's signed distance, shading normals and their
// re-posing by parallel transport.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <random>

#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>
#include <openvdb/tools/Diagnostics.h>
#include <glm/gtc/matrix_transform.hpp>

#include "libcore/config/setup.h"
#include "libcore/io/obj_io.h"
#include "libcore/io/vdb_io.h"
#include "libcore/model/strand_frames.h"
#include "libcore/volume/density_target.h"
#include "libcore/volume/shell.h"
#include "libcore/volume/splat.h"
#include "stages/grow.h"
#include "stages/interpolate.h"
#include "tests/test_util.h"

namespace hairgen {
namespace {

TEST(Volume, BoundsInParallelAreTheSerialBoundsToTheBit) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  std::vector<glm::vec3> points(1'000'000);
  for (glm::vec3& p : points) p = glm::vec3(-u(rng), u(rng), u(rng));
  // Ties of −0 and +0 at the least z and the greatest x, spread over every thread's range: the serial
  // loop keeps whichever comes first (−0 for z, +0 for x).
  for (size_t i = 1000; i < points.size(); i += 4099) {
    points[i].z = i % 2 ? 0.0f : -0.0f;
    points[i].x = i % 2 ? -0.0f : 0.0f;
  }
  const Bounds serial = bounds(points), parallel = boundsInParallel(points);
  EXPECT_EQ(0, std::memcmp(&serial, &parallel, sizeof serial));
  EXPECT_TRUE(std::signbit(parallel.min.z));
  EXPECT_FALSE(std::signbit(parallel.max.x));
}

TEST(Volume, TheSplatConservesMass) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-0.05f, 0.05f);
  std::vector<glm::vec3> points;
  for (int i = 0; i < 20000; ++i) points.push_back({u(rng), u(rng) + 0.1f, u(rng)});
  Grid g = gridAround(points, 0.004, 2);
  splat(g, points);
  double sum = 0.0;
  for (float v : g.values) sum += v;
  EXPECT_NEAR(sum, 20000.0, 20000.0 * 1e-6);
}

// Straight strands along y, their points on a 1 mm lattice, clipped to a ball of 5 cm: a body of hair
// with a known surface. Its shell sits a fraction of a voxel inside the ball (the splat's tent reaches
// out by one voxel, and iso is half the inner density), within the voxel the check allows.
TEST(Volume, TheDistanceToABallOfStrandsIsTheDistanceToItsSurface) {
  const glm::dvec3 centre(0.01, 0.02, -0.03);
  const double radius = 0.05, voxel = 0.003;
  std::vector<glm::vec3> points;
  for (int i = -50; i <= 50; ++i)
    for (int k = -50; k <= 50; ++k)
      for (int j = -50; j <= 50; ++j) {
        glm::dvec3 p = centre + 0.001 * glm::dvec3(i, j, k);
        if (glm::length(p - centre) <= radius) points.push_back(glm::vec3(p));
      }
  Grid density = gridAround(points, voxel, 4);
  splat(density, points);
  const Grid smooth = smoothed(density);
  const Grid sdf = signedDistance(smooth, 0.5 * smooth.sample(centre));
  double worst = 0.0, worstGradient = 0.0;
  int checked = 0;
  for (int k = 1; k + 1 < sdf.size.z; ++k)
    for (int j = 1; j + 1 < sdf.size.y; ++j)
      for (int i = 1; i + 1 < sdf.size.x; ++i) {
        const glm::dvec3 x = sdf.origin + voxel * glm::dvec3(i, j, k);
        const double r = glm::length(x - centre);
        worst = std::max(worst, std::abs(double(sdf.at(i, j, k)) - (r - radius)));
        if (r < 0.3 * radius) continue;  // the centre is where the distance has its kink
        const glm::dvec3 g(sdf.at(i + 1, j, k) - sdf.at(i - 1, j, k),
                           sdf.at(i, j + 1, k) - sdf.at(i, j - 1, k),
                           sdf.at(i, j, k + 1) - sdf.at(i, j, k - 1));
        worstGradient = std::max(worstGradient, std::abs(glm::length(g) / (2 * voxel) - 1.0));
        ++checked;
      }
  ASSERT_GT(checked, 10000);
  EXPECT_LT(worst, voxel) << "worst distance error, in voxels: " << worst / voxel;
  EXPECT_LT(worstGradient, 0.05);
}

struct Coupe3 : test::Job {
  Strands coupe;
  Coupe3() : test::Job(test::loadJob("thesis/coupe3/setup.txt")) {
    Hairstyle h = config.hairstyle;
    h.hairDensity = 20;
    coupe = interpolate(wick, grow(wick, h, config.collision, {}).guides, h, config.collision, {});
  }
};
const Coupe3& coupe3() {
  static const Coupe3 c;
  return c;
}

TEST(Volume, Coupe3NormalsPointAwayFromTheHeadOnTheOutside) {
  const Strands& coupe = coupe3().coupe;
  std::vector<glm::vec3> normals = volumeNormals(buildVolume(coupe, 0.004, 3, 0.25).distance, coupe);
  // The outermost vertices: those in the outer tenth of the hair's distances from the head centre,
  // direction by direction (binned by azimuth and elevation).
  const glm::dvec3 head = coupe3().config.collision.shapes[0].centre;
  std::map<std::pair<int, int>, double> farthest;
  auto bin = [&](const glm::dvec3& d) {
    return std::make_pair(int(std::floor(std::atan2(d.x, d.z) / 0.2)),
                          int(std::floor(std::asin(d.y / glm::length(d)) / 0.2)));
  };
  for (const glm::vec3& p : coupe.points) {
    glm::dvec3 d = glm::dvec3(p) - head;
    double& f = farthest[bin(d)];
    f = std::max(f, glm::length(d));
  }
  int outer = 0, away = 0;
  for (size_t i = 0; i < coupe.pointCount(); ++i) {
    glm::dvec3 d = glm::dvec3(coupe.points[i]) - head;
    if (glm::length(d) < farthest[bin(d)] - 0.005) continue;
    ++outer;
    away += glm::dot(glm::dvec3(normals[i]), d) > 0.0;
  }
  ASSERT_GT(outer, 500);
  EXPECT_GE(double(away) / outer, 0.95) << away << " of " << outer;
}

// shade without --vdb slides only the nodes the normals read: the normals must be the same bits as with
// the whole grid's distance, there and on a coupe whose points sit on the grid's planes (cells whose
// upper corners weigh nothing), and the nodes left out must be a real part of the grid.
TEST(Volume, NormalsFromTheDistanceWhereTheyReadItAreTheWholeGridsBits) {
  Strands snapped = coupe3().coupe;
  for (glm::vec3& p : snapped.points) p = glm::round(p / 0.004f) * 0.004f;
  // Padding 0 puts vertices in the grid's last cells, where the corners and the gradients' neighbours
  // are clamped.
  for (const auto& [coupe, padding] :
       {std::pair{&coupe3().coupe, 3}, std::pair{static_cast<const Strands*>(&snapped), 3},
        std::pair{&coupe3().coupe, 0}}) {
    const HairVolume whole = buildVolume(*coupe, 0.004, padding, 0.25, true),
                     part = buildVolume(*coupe, 0.004, padding, 0.25, false);
    const std::vector<uint8_t> read = nodesNormalsRead(part.distance, coupe->points);
    size_t flagged = 0, differ = 0;
    for (size_t id = 0; id < read.size(); ++id) {
      flagged += read[id];
      if (read[id]) {
        EXPECT_EQ(whole.distance.values[id], part.distance.values[id]) << id;
      }
      differ += whole.distance.values[id] != part.distance.values[id];
    }
    EXPECT_LT(flagged, read.size() * 3 / 4);
    EXPECT_GT(differ, 0u);
    EXPECT_TRUE(volumeNormals(whole.distance, *coupe) == volumeNormals(part.distance, *coupe));
  }
}

TEST(Volume, ReposingOntoTheRestPoseGivesTheRestNormals) {
  Strands rest = coupe3().coupe;
  rest.normals = volumeNormals(buildVolume(rest, 0.004, 3, 0.25).distance, rest);
  Strands same = rest;
  same.normals.clear();
  std::vector<glm::vec3> reposed = reposeNormals(rest, same);
  double worst = 0.0;
  for (size_t i = 0; i < reposed.size(); ++i)
    worst = std::max(worst, double(glm::length(reposed[i] - rest.normals[i])));
  EXPECT_LT(worst, 1e-6);
}

TEST(Volume, ReposingRestNormalsOnARotatedCoupeRotatesThem) {
  Strands rest = coupe3().coupe;
  rest.normals = volumeNormals(buildVolume(rest, 0.004, 3, 0.25).distance, rest);
  const glm::dmat3 r =
      glm::dmat3(glm::rotate(glm::dmat4(1.0), 0.7, glm::normalize(glm::dvec3(0.3, 1.0, -0.4))));
  Strands moved = rest;
  for (glm::vec3& p : moved.points) p = glm::vec3(r * glm::dvec3(p) + glm::dvec3(0.1, -0.2, 0.05));
  for (glm::vec3& t : moved.tangents) t = glm::vec3(r * glm::dvec3(t));
  moved.normals.clear();
  std::vector<glm::vec3> reposed = reposeNormals(rest, moved);
  double worst = 0.0;
  for (size_t i = 0; i < reposed.size(); ++i)
    worst = std::max(worst, glm::length(glm::dvec3(reposed[i]) - r * glm::dvec3(rest.normals[i])));
  EXPECT_LT(worst, 1e-5);
}

// shade --vdb by OpenVDB's conventions (issue 36): the density a fog volume in [0, 1] with its scale
// in the grid's metadata, the distance a narrow-band level set; both pass OpenVDB's own diagnostics
// (every check: for the level set, |grad| near 1 at the zero crossings too).
TEST(Volume, TheVdbGridsPassOpenVdbsFogVolumeAndLevelSetChecks) {
  const Strands& coupe = coupe3().coupe;
  const HairVolume volume = buildVolume(coupe, 0.004, 3, 0.25, true);
  test::TempDir dir("vdb");
  writeVdb(dir / "hair.vdb", volume);
  openvdb::initialize();
  openvdb::io::File file((dir / "hair.vdb").string());
  file.open();
  const auto density = openvdb::gridPtrCast<openvdb::FloatGrid>(file.readGrid("density"));
  const auto sdf = openvdb::gridPtrCast<openvdb::FloatGrid>(file.readGrid("sdf"));
  file.close();
  ASSERT_TRUE(density && sdf);
  EXPECT_EQ(openvdb::tools::checkFogVolume(*density), "");
  EXPECT_EQ(openvdb::tools::checkLevelSet(*sdf), "");
  // The scale: a node's points per voxel is its fog value times the metadata's.
  const double scale = density->metaValue<double>("hairgen_points_per_voxel_at_1");
  const float largest = *std::max_element(volume.density.values.begin(), volume.density.values.end());
  EXPECT_EQ(scale, double(largest));
  const openvdb::Coord at(volume.density.size.x / 2, volume.density.size.y / 2, volume.density.size.z / 2);
  EXPECT_NEAR(density->tree().getValue(at) * scale, volume.density.at(at.x(), at.y(), at.z()), 1e-5 * scale);
  EXPECT_NEAR(density->metaValue<double>("hairgen_shell_density") * scale, volume.iso, 1e-9 * scale);
  // A narrow band, its background 3 voxels; its values hairgen's distance smoothed by one Gaussian
  // pass (measured on this volume: 0.19 voxels on average, 6% of the band by more than half a voxel,
  // where wisps thinner than a voxel are taken out).
  EXPECT_FLOAT_EQ(sdf->background(), float(3 * 0.004));
  EXPECT_LT(sdf->activeVoxelCount(), volume.distance.values.size() / 4);
  size_t active = 0, moved = 0;
  double sum = 0.0;
  for (auto v = sdf->cbeginValueOn(); v; ++v) {
    const openvdb::Coord c = v.getCoord();
    ASSERT_LE(std::abs(*v), sdf->background());
    const double by = std::abs(*v - volume.distance.at(c.x(), c.y(), c.z()));
    ++active;
    sum += by;
    moved += by > 0.5 * 0.004;
  }
  EXPECT_LT(double(moved), 0.08 * double(active))
      << moved << " of " << active << " moved by more than half a voxel";
  EXPECT_LT(sum / double(active), 0.25 * 0.004) << "mean move " << sum / double(active) / 0.004 << " voxels";
}

}  // namespace
}  // namespace hairgen
