// The shot stage (stages/shot.h): the frame `run` and `render --guides --frames` both render. At the
// rest frame with a still head it is the rest coupe; shaded, it takes the rest's normals and colours;
// the head moves with its keys; a frame's motion is from the frame before, the first's from itself.
#include <gtest/gtest.h>

#include "libcore/config/setup.h"
#include "stages/grow.h"
#include "stages/interpolate.h"
#include "stages/shot.h"
#include "tests/test_util.h"

namespace hairgen {
namespace {

// Coupe 2 at a low density (its guides are the cheapest to grow), grown once for the tests.
struct Grown : test::Job {
  Strands guides;
  Grown() : test::Job(test::loadJob("thesis/coupe2/setup.txt", SetupUse::kInterpolate)) {
    config.hairstyle.hairDensity = 20;
    guides = grow(wick, config.hairstyle, config.collision, {}).guides;
  }
};
const Grown& grown() {
  static const Grown g;
  return g;
}

Strands restCoupe() {
  const Grown& g = grown();
  return interpolate(g.wick, g.guides, g.config.hairstyle, g.config.collision, {g.config.digest(), "g.hair"});
}

TEST(Shot, TheRestFrameWithAStillHeadIsTheRestCoupe) {
  const Grown& g = grown();
  const Mesh& head = g.wick;  // any mesh stands for the head
  const ShotInputs inputs{&g.config, &g.wick, nullptr, &head, HeadMotion{}, false};
  const ShotFrame frame = shotFrame(inputs, 7, g.guides, "g.hair");
  const Strands rest = restCoupe();
  ASSERT_GT(rest.strandCount(), 100u);
  EXPECT_EQ(frame.coupe, rest);
  ASSERT_TRUE(frame.head);
  EXPECT_EQ(frame.head->positions, head.positions);
  EXPECT_FALSE(shotHead({&g.config, &g.wick, nullptr, nullptr, HeadMotion{}, false}, 7));
}

TEST(Shot, AShadedShotTakesTheRestsNormalsAndColours) {
  const Grown& g = grown();
  Strands shaded = restCoupe();
  shaded.normals.assign(shaded.pointCount(), glm::vec3(0, 0, 1));
  shaded.colors.assign(shaded.pointCount(), glm::vec3(0.25f, 0.5f, 0.75f));
  const ShotInputs inputs{&g.config, &g.wick, &shaded, nullptr, HeadMotion{}, false};
  const ShotFrame frame = shotFrame(inputs, 0, g.guides, "g.hair");
  EXPECT_EQ(frame.coupe.points, shaded.points);
  EXPECT_EQ(frame.coupe.colors, shaded.colors);
  ASSERT_EQ(frame.coupe.normals.size(), shaded.normals.size());
  for (size_t i = 0; i < shaded.normals.size(); ++i)
    ASSERT_LT(glm::length(frame.coupe.normals[i] - shaded.normals[i]), 1e-5f) << "point " << i;
  EXPECT_FALSE(frame.head);
}

TEST(Shot, TheHeadMovesWithItsKeys) {
  const Grown& g = grown();
  HeadKey turn;
  turn.frame = 10.0;
  turn.rotation = glm::dvec3(0.0, 30.0, 0.0);
  const HeadMotion motion({HeadKey{}, turn}, glm::dvec3(0.0, 0.1, 0.0), 24.0);
  const ShotInputs inputs{&g.config, &g.wick, nullptr, &g.wick, motion, false};
  const std::optional<Mesh> head = shotHead(inputs, 10);
  ASSERT_TRUE(head);
  EXPECT_EQ(head->positions, posedMesh(g.wick, motion.pose(10)).positions);
  EXPECT_NE(head->positions, g.wick.positions);
}

TEST(Shot, AFramesMotionIsFromTheFrameBeforeAndTheFirstsFromItself) {
  Mesh headA, headB;
  headA.positions = {glm::vec3(0, 0, 0)};
  headB.positions = {glm::vec3(1, 0, 0)};
  ShotFrame a{test::sampleStrands(7, 1), headA}, b{test::sampleStrands(7, 2), headB};
  ShotMotion motion;
  EXPECT_FALSE(motion.started());
  const FrameBefore first = motion.before(a);  // nothing before the shot: the frame itself
  ASSERT_TRUE(first.hair && first.head);
  EXPECT_EQ(*first.hair, a.coupe);
  EXPECT_EQ(first.head->positions, headA.positions);
  motion.keep(ShotFrame(a));
  const FrameBefore second = motion.before(b);
  ASSERT_TRUE(second.hair && second.head);
  EXPECT_EQ(*second.hair, a.coupe);
  EXPECT_EQ(second.head->positions, headA.positions);
  motion.keep(std::move(b));
  EXPECT_EQ(*motion.before(a).hair, test::sampleStrands(7, 2));
}

}  // namespace
}  // namespace hairgen
