// The grow stage: guides at the static equilibrium the thesis' energy defines.
#include <gtest/gtest.h>

#include <tbb/global_control.h>

#include "libcore/error.h"
#include "libcore/obj_io.h"
#include "libcore/setup.h"
#include "stages/grow.h"
#include "tests/test_util.h"

namespace hairgen {
namespace {

Hairstyle style(std::vector<double> lengths) {
  Hairstyle h;
  h.hairLengths = std::move(lengths);
  return h;
}

std::vector<glm::dvec3> shape(const RodFrame& root, const Hairstyle& h, const std::vector<double>& q) {
  std::vector<glm::dvec3> p;
  std::vector<double> s = sampleArcLengths(h.totalLength(), h.visualityStep, true);
  sampleRod(root, h.hairLengths, q, s, p, nullptr);
  return p;
}

TEST(Grow, WithoutGravityOrCollisionsEveryGuideIsItsRestHelix) {
  Hairstyle h = style({0.04, 0.04, 0.04, 0.04});
  h.gravity = 0.0;
  h.helixRadius = 0.025;
  h.helixStep = 0.025;
  RodFrame root = follicleFrame({0, 0.15, 0}, {0.2, 1, 0.1});
  GuideReport r = growGuide(root, 0.5, h, Collision{});
  RestShape rest = restShape(h.helixRadius, h.helixStep);
  for (size_t e = 0; e < 4; ++e) {
    EXPECT_DOUBLE_EQ(r.coordinates[3 * e], rest.tau);
    EXPECT_DOUBLE_EQ(r.coordinates[3 * e + 1], rest.kappa1);
  }
  EXPECT_EQ(r.end.total(), 0.0);
}

TEST(Grow, WithNegligibleElasticityAGuideHangsStraightDown) {
  Hairstyle h = style(std::vector<double>(4, 0.04));
  h.young = 1.0;  // pascals: nothing resists gravity
  h.maxIter = 200;
  h.epsilon = 1e-12;
  RodFrame root = follicleFrame({0, 0.15, 0}, {0.0, -1.0, 0.05});
  GuideReport r = growGuide(root, 0.0, h, Collision{});
  std::vector<glm::dvec3> p = shape(root, h, r.coordinates);
  glm::dvec3 below = root.position - glm::dvec3(0, 0.16, 0);
  EXPECT_LT(glm::length(p.back() - below), 0.002) << "tip at " << p.back().x << " " << p.back().y << " " << p.back().z;
}

TEST(Grow, Coupe3LongGuidesHangBelowTheirRootsAndStayOutOfTheHead) {
  Config c = loadConfig(test::sourceDir() / "configs/thesis/coupe3/setup.txt", {}, SetupUse::kGrow);
  Mesh wick = readObj(c.setup.wickModel.path);
  GrowResult g = grow(wick, c.hairstyle, c.collision, {});
  const CollisionShape& head = c.collision.shapes[0];
  size_t below = 0;
  double deepest = 0.0;
  for (size_t i = 0; i < g.guides.strandCount(); ++i) {
    const glm::vec3 root = g.guides.points[g.guides.firstPoint[i]];
    const glm::vec3 tip = g.guides.points[g.guides.firstPoint[i + 1] - 1];
    below += tip.y < root.y;
    for (uint32_t p = g.guides.firstPoint[i] + 2; p < g.guides.firstPoint[i + 1]; ++p)
      deepest = std::max(deepest, penetration(head, glm::dvec3(g.guides.points[p])));
  }
  // Measured: 735 of 759 tips end below their roots; the rest are crown guides held up by the 4 cm
  // envelope. Hair does not enter the head ellipsoid itself by more than 2 mm.
  EXPECT_GE(below, g.guides.strandCount() * 95 / 100);
  EXPECT_LT(deepest, 0.002);
}

TEST(Grow, OutputIsIdenticalForAnyThreadCount) {
  Config c = loadConfig(test::sourceDir() / "configs/thesis/coupe2/setup.txt", {}, SetupUse::kGrow);
  Mesh wick = readObj(c.setup.wickModel.path);
  wick.positions.resize(120);
  wick.normals.resize(120);
  wick.triangles.clear();
  Strands a, b;
  {
    tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
    a = grow(wick, c.hairstyle, c.collision, {}).guides;
  }
  b = grow(wick, c.hairstyle, c.collision, {}).guides;
  EXPECT_TRUE(a == b);
}

TEST(Grow, ZeroNormalIsAnInputError) {
  Mesh wick;
  wick.positions = {{0, 0, 0}};
  wick.normals = {{0, 0, 0}};
  EXPECT_THROW(grow(wick, style({0.01}), Collision{}, {}), InputError);
}

}  // namespace
}  // namespace hairgen
