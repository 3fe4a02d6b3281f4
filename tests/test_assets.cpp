// The bundled head and wick (configs/assets): generated, fitted to the thesis' head ellipsoid.
#include <gtest/gtest.h>

#include <sstream>

#include "libcore/assets/head_generator.h"
#include "libcore/io/obj_io.h"
#include "libcore/util/file_util.h"
#include "tests/test_util.h"

namespace hairgen {
namespace {

std::filesystem::path assets() {
  return test::sourceDir() / "configs" / "assets";
}

TEST(Assets, GeneratorReproducesTheCommittedFilesByteForByte) {
  test::TempDir dir("assets");
  HeadAssetParams params;
  writeHeadAssets(dir.path(), params, generateHeadAssets(params));
  for (const char* file : {"head.obj", "wick.obj", "assets.txt"})
    EXPECT_TRUE(readFileText(dir / file) == readFileText(assets() / file))
        << file << " differs: run `hairgen assets`";
}

TEST(Assets, WickLiesJustInsideTheHeadEllipsoid) {
  HeadAssetParams params;
  Mesh wick = readObj(assets() / "wick.obj");
  for (const glm::vec3& p : wick.positions) {
    double r = glm::length((glm::dvec3(p) - params.ellipsoidCentre) / params.ellipsoidAxes);
    EXPECT_LT(r, 1.0);
    EXPECT_GT(r, 0.99);
  }
}

TEST(Assets, WickNormalsPointOutward) {
  HeadAssetParams params;
  Mesh wick = readObj(assets() / "wick.obj");
  for (size_t i = 0; i < wick.vertexCount(); ++i) {
    glm::dvec3 p = glm::dvec3(wick.positions[i]) - params.ellipsoidCentre;
    glm::dvec3 gradient = glm::normalize(p / (params.ellipsoidAxes * params.ellipsoidAxes));
    EXPECT_NEAR(glm::length(wick.normals[i]), 1.0, 1e-3);
    EXPECT_GT(glm::dot(glm::dvec3(wick.normals[i]), gradient), 0.999);
  }
  // The triangles wind outward too, so area-weighted normals agree.
  std::vector<glm::vec3> fromFaces = areaWeightedNormals(wick.positions, wick.triangles);
  for (size_t i = 0; i < wick.vertexCount(); ++i) EXPECT_GT(glm::dot(fromFaces[i], wick.normals[i]), 0.95f);
}

TEST(Assets, WickVerticesAreAboutOneCentimetreApart) {
  Mesh wick = readObj(assets() / "wick.obj");
  double sum = 0.0, shortest = 1.0, longest = 0.0;
  for (const glm::uvec3& t : wick.triangles)
    for (int c = 0; c < 3; ++c) {
      double e = glm::length(wick.positions[t[c]] - wick.positions[t[(c + 1) % 3]]);
      sum += e;
      shortest = std::min(shortest, e);
      longest = std::max(longest, e);
    }
  double mean = sum / (3.0 * wick.triangleCount());
  EXPECT_GT(mean, 0.008);
  EXPECT_LT(mean, 0.012);
  EXPECT_GT(shortest, 0.004);
  EXPECT_LT(longest, 0.018);
  EXPECT_GT(wick.vertexCount(), 500u);
}

TEST(Assets, WickCoversCrownAndNapeButNotTheFace) {
  HeadAssetParams params;
  Mesh wick = readObj(assets() / "wick.obj");
  Bounds b = bounds(wick.positions);
  glm::dvec3 c = params.ellipsoidCentre, a = params.ellipsoidAxes;
  EXPECT_GT(b.max.y, c.y + 0.98 * a.y);  // the crown
  EXPECT_LT(b.min.z, c.z - 0.95 * a.z);  // the back of the head
  for (const glm::vec3& p : wick.positions) {
    glm::dvec3 u = (glm::dvec3(p) - c) / a;
    if (u.z > 0.9) {
      EXPECT_GT(u.y, 0.3) << "hair on the face";
    }
  }
}

TEST(Assets, FolliclesSitOnTopOfTheHeadSurface) {
  HeadAssetParams params;
  Mesh wick = readObj(assets() / "wick.obj");
  for (const glm::vec3& p : wick.positions) {
    double d = headDistance(params, glm::dvec3(p));
    EXPECT_GT(d, 0.0) << "follicle buried in the head";
    EXPECT_LT(d, 0.004) << "follicle floating above the scalp";
  }
}

TEST(Assets, HeadFitsTheEllipsoidWithFaceAlongPlusZ) {
  HeadAssetParams params;
  Mesh head = readObj(assets() / "head.obj");
  Bounds b = bounds(head.positions);
  glm::dvec3 c = params.ellipsoidCentre, a = params.ellipsoidAxes;
  EXPECT_NEAR(b.max.y, c.y + params.craniumScale * a.y, 0.003);  // crown = top of the ellipsoid
  EXPECT_GT(b.max.z, c.z + a.z);                                 // the nose sticks out in front
  EXPECT_LT(b.min.y, c.y - 2.0 * a.y);                           // jaw and neck below the cranium
  // Above the brow the head is the (slightly shrunk) ellipsoid.
  for (const glm::vec3& p : head.positions) {
    glm::dvec3 u = (glm::dvec3(p) - c) / a;
    if (u.y > 0.3) {
      EXPECT_LT(glm::length(u), 1.0);
    }
  }
}

}  // namespace
}  // namespace hairgen
