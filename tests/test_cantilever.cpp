// Anjyo's cantilever styling and per-strand ambient: properties the beam model and the configs promise.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "libcore/config/setup.h"
#include "libcore/io/obj_io.h"
#include "libcore/physics/cantilever.h"
#include "stages/grow.h"
#include "stages/shade.h"
#include "tests/test_util.h"

namespace hairgen {
namespace {

Hairstyle beam(double length, int segments) {
  Hairstyle h;
  h.model = StylingModel::kCantilever;
  h.hairLengths = {length};
  h.segments = segments;
  return h;
}

double turnDegrees(const glm::dvec3& a, const glm::dvec3& b) {
  return glm::degrees(std::atan2(glm::length(glm::cross(a, b)), glm::dot(a, b)));
}

struct Bob : test::Job {
  Bob() : test::Job(test::loadJob("anjyo/bob/setup.txt")) {}
  const CollisionShape* head() const { return &config.collision.shapes.at(0); }
};
const Bob& bob() {
  static const Bob b;
  return b;
}

TEST(Cantilever, WithoutForceAHairStaysStraightAlongItsFollicle) {
  Hairstyle h = beam(0.2, 20);
  h.gravity = 0.0;
  const glm::dvec3 pore(0.01, 0.1, -0.02), normal = glm::normalize(glm::dvec3(0.3, 1.0, -0.2));
  std::vector<glm::dvec3> p = bendHair(pore, normal, h, nullptr);
  ASSERT_EQ(p.size(), 21u);
  for (size_t i = 0; i < p.size(); ++i)
    EXPECT_LT(glm::length(p[i] - (pore + 0.01 * double(i) * normal)), 1e-12);
}

TEST(Cantilever, AHorizontalHairDeflectsDownMoreWhenLongerLessWhenStiffer) {
  auto tipDrop = [](double length, double rigidity) {
    Hairstyle h = beam(length, 20);
    h.flexuralRigidity = rigidity;
    std::vector<glm::dvec3> p = bendHair(glm::dvec3(0.0), glm::dvec3(1, 0, 0), h, nullptr);
    return -p.back().y;
  };
  const double ei = 7e-9;
  EXPECT_GT(tipDrop(0.10, ei), 0.0);
  EXPECT_GT(tipDrop(0.20, ei), tipDrop(0.10, ei));
  EXPECT_LT(tipDrop(0.10, 2 * ei), tipDrop(0.10, ei));
}

TEST(Cantilever, ASingleSegmentDeflectsByEquationThree) {
  Hairstyle h = beam(0.02, 1);
  h.flexuralRigidity = 1e-10;
  std::vector<glm::dvec3> p = bendHair(glm::dvec3(0.0), glm::dvec3(1, 0, 0), h, nullptr);
  const double d = 0.02, load = h.massDensity * M_PI * h.hairRadius1 * h.hairRadius2 * h.gravity * d;
  const double moment = -load * d * 1.0 / 2.0;                    // (2) with k = i = 1
  const double y = -0.5 * (moment / h.flexuralRigidity) * d * d;  // (3)
  EXPECT_DOUBLE_EQ(cantileverDeflection(load, d, h.flexuralRigidity, 1, 1), y);
  // p1 = p0 + d e/|e| with e = d a0 + y (down).
  const double n = std::hypot(d, y);
  EXPECT_NEAR(p[1].x, d * d / n, 1e-15);
  EXPECT_NEAR(p[1].y, -d * y / n, 1e-15);
  EXPECT_GT(y, 0.0);
}

TEST(Cantilever, SegmentsKeepTheirLengthAndNoNodeOfTheBobEntersTheHead) {
  const Bob& b = bob();
  Hairstyle h = b.config.hairstyle;
  h.cuts.clear();
  const double d = h.totalLength() / h.segments;
  double worstLength = 0.0, innermost = HUGE_VAL;
  for (size_t i = 0; i < b.wick.vertexCount(); ++i) {
    std::vector<glm::dvec3> p =
        bendHair(glm::dvec3(b.wick.positions[i]), glm::dvec3(b.wick.normals[i]), h, b.head());
    for (size_t n = 1; n < p.size(); ++n) {
      worstLength = std::max(worstLength, std::abs(glm::length(p[n] - p[n - 1]) - d) / d);
      glm::dvec3 local = (p[n] - b.head()->centre) / b.head()->halfExtents;
      innermost = std::min(innermost, glm::length(local));
    }
  }
  EXPECT_LT(worstLength, 1e-9);
  EXPECT_GE(innermost, 1.0 - 1e-9) << "a node lies inside the head ellipsoid";
}

// The cantilever turns hair out of headShape (params.h): behind a decoy Ellipsoid far away, the bob's head
// fitted to the head mesh shapes the guides exactly as when it is alone.
TEST(Cantilever, GrowTurnsHairOutOfTheHeadShape) {
  const Bob& b = bob();
  Hairstyle h = b.config.hairstyle;
  h.cuts.clear();
  Collision alone, decoyFirst;
  alone.shapes = {*b.head()};
  decoyFirst.shapes = {*b.head(), *b.head()};
  decoyFirst.shapes[0].centre = glm::dvec3(1000.0, 0.0, 0.0);
  decoyFirst.shapes[1].fitted = true;
  const Strands expected = growCantilever(b.wick, h, alone, GrowOptions{}).guides;
  Collision decoyAlone;
  decoyAlone.shapes = {decoyFirst.shapes[0]};
  const Strands unturned = growCantilever(b.wick, h, decoyAlone, GrowOptions{}).guides;
  ASSERT_FALSE(std::equal(unturned.points.begin(), unturned.points.end(), expected.points.begin()))
      << "the head must turn some hair for the test to mean anything";
  const Strands got = growCantilever(b.wick, h, decoyFirst, GrowOptions{}).guides;
  ASSERT_EQ(got.points.size(), expected.points.size());
  EXPECT_TRUE(std::equal(got.points.begin(), got.points.end(), expected.points.begin()));
}

TEST(Cantilever, ACutRemovesExactlyTheSegmentsBelowItsHeightForItsPores) {
  const Bob& b = bob();
  Hairstyle uncut = b.config.hairstyle;
  uncut.cuts.clear();
  Hairstyle cut = uncut;
  cut.cuts.push_back({-40.0, 40.0, 180.0, 0.09, {}});  // the front, above the brows
  int selected = 0, shortened = 0;
  for (size_t i = 0; i < b.wick.vertexCount(); ++i) {
    std::vector<glm::dvec3> full =
        bendHair(glm::dvec3(b.wick.positions[i]), glm::dvec3(b.wick.normals[i]), uncut, b.head());
    std::vector<glm::dvec3> kept = full;
    cutHair(kept, cut, b.head());
    glm::dvec2 polar = porePolar(full.front(), b.head());
    if (polar.x >= -40.0 && polar.x <= 40.0) {
      ++selected;
      size_t firstBelow = full.size();
      for (size_t n = 1; n < full.size(); ++n)
        if (full[n].y < 0.09) {
          firstBelow = n;
          break;
        }
      ASSERT_EQ(kept.size(), firstBelow) << "pore " << i;
      shortened += kept.size() < full.size();
    } else {
      ASSERT_EQ(kept.size(), full.size()) << "pore " << i << " is not selected but was cut";
    }
    for (size_t n = 0; n < kept.size(); ++n) ASSERT_EQ(kept[n], full[n]);
  }
  EXPECT_GT(selected, 50);
  EXPECT_GT(shortened, 50);
}

TEST(Cantilever, TheJointAngleLimitHoldsAtEveryNode) {
  Hairstyle h = beam(0.25, 25);
  h.jointLimit = 10.0;
  h.jointLimitFrom = 2;
  h.forces.push_back({glm::dvec3(30, 0, 0), ForceField::Region::kAbove, 0.05, {}, {}, {}, {}});
  for (glm::dvec3 normal : {glm::dvec3(1, 0, 0), glm::dvec3(0, 1, 0), glm::dvec3(-0.3, 0.2, 1.0)}) {
    std::vector<glm::dvec3> p = bendHair(glm::dvec3(0.0), glm::normalize(normal), h, nullptr);
    double largest = 0.0;
    for (size_t n = 2; n + 1 < p.size(); ++n) {
      double turn = turnDegrees(p[n] - p[n - 1], p[n + 1] - p[n]);
      EXPECT_LE(turn, 10.0 + 1e-9) << "node " << n;
      largest = std::max(largest, turn);
    }
    EXPECT_GT(largest, 9.0) << "the limit never came into play";
  }
}

TEST(Shade, PerStrandAmbientHasItsMeanAndDeviationAndRepeats) {
  Strands s;
  for (int i = 0; i < 10000; ++i) s.addStrand({glm::vec3(0, 0, 0), glm::vec3(0, 0.01f, 0)});
  for (int i = 0; i < 10000; ++i) s.strandId.push_back(uint32_t(7 * i + 3));
  Visuality v;
  v.ambientMean = 0.8;
  v.ambientDeviation = 0.1;
  const RenderSettings r;
  Strands a = shade(s, v, r, {42, "x"}).coupe, b = shade(s, v, r, {42, "x"}).coupe;
  EXPECT_TRUE(a == b);
  double sum = 0.0, sum2 = 0.0;
  for (size_t i = 0; i < a.strandCount(); ++i) {
    const glm::vec3 c = a.colors[a.firstPoint[i]];
    ASSERT_EQ(c, a.colors[a.firstPoint[i] + 1]);
    sum += c.x;
    sum2 += double(c.x) * c.x;
  }
  const double mean = sum / 10000, deviation = std::sqrt(sum2 / 10000 - mean * mean);
  EXPECT_NEAR(mean, 0.8, 0.02 * 0.8);
  EXPECT_NEAR(deviation, 0.1, 0.02 * 0.1);
  EXPECT_FALSE(a == shade(s, v, r, {43, "x"}).coupe);
}

}  // namespace
}  // namespace hairgen
