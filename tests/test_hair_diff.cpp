// hairgen diff on caches: the structure must match exactly, points within a distance, normals within an
// angle, colours within a 16-bit step, and a non-finite value never passes.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "libcore/io/hair_diff.h"

namespace hairgen {
namespace {

// Two strands of three points hanging down from y = 0.1, 1 cm apart, with ids and normals.
Strands twoStrands() {
  Strands s;
  for (int k = 0; k < 2; ++k)
    s.addStrand({{0.01f * k, 0.1f, 0.0f}, {0.01f * k, 0.09f, 0.0f}, {0.01f * k, 0.08f, 0.0f}});
  s.strandId = {7, 9};
  s.normals.assign(s.pointCount(), glm::vec3(0.0f, 0.0f, 1.0f));
  return s;
}

TEST(HairDiff, EqualCachesPass) {
  const HairDiff d = diffHair(twoStrands(), twoStrands(), {});
  EXPECT_EQ(d.code, ExitCode::kSuccess);
  EXPECT_TRUE(d.structureMatches);
  EXPECT_EQ(d.strands, 2u);
  EXPECT_EQ(d.points, 6u);
  EXPECT_EQ(d.maxDistance, 0.0);
  EXPECT_TRUE(d.normalsCompared);
  EXPECT_FALSE(d.colorsCompared);
}

TEST(HairDiff, APointPastTheToleranceFailsAndIsLocated) {
  Strands b = twoStrands();
  b.points[5].x += 2.0e-5f;  // the tip of strand 1, 20 µm: past the default 10 µm
  HairDiff d = diffHair(twoStrands(), b, {});
  EXPECT_EQ(d.code, ExitCode::kDiffFailed);
  EXPECT_NEAR(d.maxDistance, 2.0e-5, 1e-9);
  EXPECT_NEAR(d.meanDistance, 2.0e-5 / 6.0, 1e-9);
  EXPECT_EQ(d.worstStrand, 1u);
  EXPECT_EQ(d.worstPoint, 2u);
  EXPECT_NE(d.reason.find("strand 1"), std::string::npos) << d.reason;
  d = diffHair(twoStrands(), b, {.distance = 3.0e-5});
  EXPECT_EQ(d.code, ExitCode::kSuccess) << d.reason;
}

TEST(HairDiff, RootsMatchExactlyWhateverTheTolerance) {
  Strands b = twoStrands();
  b.points[3].y = std::nextafter(b.points[3].y, 1.0f);  // strand 1's root, one float step up
  const HairDiff d = diffHair(twoStrands(), b, {.distance = 1.0});
  EXPECT_EQ(d.code, ExitCode::kDiffFailed);
  EXPECT_FALSE(d.structureMatches);
  EXPECT_NE(d.reason.find("strand 1's root moved"), std::string::npos) << d.reason;
}

TEST(HairDiff, StrandCountPointsPerStrandAndIdsMatchExactly) {
  Strands fewer = twoStrands();
  fewer.points.resize(3);
  fewer.firstPoint.resize(2);
  fewer.strandId.resize(1);
  fewer.normals.resize(3);
  EXPECT_NE(diffHair(twoStrands(), fewer, {.distance = 1.0}).reason.find("2 strands, the other 1"),
            std::string::npos);

  Strands shorter;  // the same roots, strand 0 one point shorter
  shorter.addStrand({{0.0f, 0.1f, 0.0f}, {0.0f, 0.09f, 0.0f}});
  shorter.addStrand({{0.01f, 0.1f, 0.0f}, {0.01f, 0.09f, 0.0f}, {0.01f, 0.08f, 0.0f}, {0.01f, 0.07f, 0.0f}});
  EXPECT_NE(diffHair(twoStrands(), shorter, {.distance = 1.0}).reason.find("strand 0 has 3 points"),
            std::string::npos);

  Strands renumbered = twoStrands();
  renumbered.strandId[1] = 8;
  EXPECT_NE(diffHair(twoStrands(), renumbered, {.distance = 1.0}).reason.find("strand 1 has id 9"),
            std::string::npos);
}

TEST(HairDiff, NormalsWithinAnAngle) {
  Strands b = twoStrands();
  const double turn = 0.2 * M_PI / 180.0;  // 0.2 degrees about y
  b.normals[4] = glm::vec3(float(std::sin(turn)), 0.0f, float(std::cos(turn)));
  HairDiff d = diffHair(twoStrands(), b, {});
  EXPECT_EQ(d.code, ExitCode::kDiffFailed);
  EXPECT_NEAR(d.maxAngleDegrees, 0.2, 1e-4);
  EXPECT_EQ(diffHair(twoStrands(), b, {.angleDegrees = 0.3}).code, ExitCode::kSuccess);

  b.normals.clear();
  d = diffHair(twoStrands(), b, {});
  EXPECT_EQ(d.reason, "the other has no normals");
}

TEST(HairDiff, ColoursWithinOneSixteenBitStep) {
  Strands a = twoStrands();
  a.colors.assign(a.pointCount(), glm::vec3(0.8f));
  Strands b = a;
  b.colors[2].y += 5.0e-6f;
  EXPECT_EQ(diffHair(a, b, {}).code, ExitCode::kSuccess);
  b.colors[2].y += 2.0e-5f;
  const HairDiff d = diffHair(a, b, {});
  EXPECT_EQ(d.code, ExitCode::kDiffFailed);
  EXPECT_NEAR(d.maxColor, 2.5e-5, 1e-7);
}

TEST(HairDiff, ANonFiniteValueNeverPasses) {
  Strands b = twoStrands();
  b.points[4].z = std::numeric_limits<float>::quiet_NaN();  // a NaN compares false with any tolerance
  EXPECT_EQ(diffHair(twoStrands(), b, {.distance = 1.0}).code, ExitCode::kDiffFailed);
  b = twoStrands();
  b.normals[1].x = std::numeric_limits<float>::infinity();
  EXPECT_EQ(diffHair(twoStrands(), b, {.angleDegrees = 180.0}).code, ExitCode::kDiffFailed);
}

}  // namespace
}  // namespace hairgen
