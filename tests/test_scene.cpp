// Real heads (README, Real heads): meshes read in other units, axes and groups, shapes fitted to a head,
// the scene check, follicle inclination.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "libcore/io/obj_io.h"
#include "libcore/model/shape_fit.h"
#include "libcore/util/error.h"
#include "stages/preflight/scene.h"

namespace hairgen {
namespace {

// Points on an axis-aligned ellipsoid, the upper `cap` of it (1 = all of it).
std::vector<glm::vec3> onEllipsoid(glm::dvec3 centre, glm::dvec3 axes, double cap) {
  std::vector<glm::vec3> out;
  for (int i = 0; i <= 40; ++i)
    for (int j = 0; j < 40; ++j) {
      const double theta = M_PI * cap * i / 40.0, phi = 2 * M_PI * j / 40.0;
      out.push_back(glm::vec3(centre + axes * glm::dvec3(std::sin(theta) * std::cos(phi), std::cos(theta),
                                                         std::sin(theta) * std::sin(phi))));
    }
  return out;
}

TEST(ShapeFit, EllipsoidThroughItsOwnPointsIsExact) {
  const glm::dvec3 centre(0.01, 1.7, -0.02), axes(0.08, 0.09, 0.11);
  const EllipsoidFit e = fitAlignedEllipsoid(onEllipsoid(centre, axes, 1.0));
  ASSERT_TRUE(e.valid);
  EXPECT_NEAR(glm::length(e.centre - centre), 0.0, 1e-5);
  EXPECT_NEAR(glm::length(e.semiAxes - axes), 0.0, 1e-5);
  const SphereFit s = fitSphere(onEllipsoid(centre, glm::dvec3(0.1), 0.4));  // a cap: a scalp
  EXPECT_NEAR(glm::length(s.centre - centre), 0.0, 1e-5);
  EXPECT_NEAR(s.radius, 0.1, 1e-5);
}

TEST(ShapeFit, RootsOfAScalpLieOnOrOutsideTheFittedHead) {
  const std::vector<glm::vec3> scalp = onEllipsoid({0, 1.7, 0}, {0.08, 0.085, 0.1}, 0.45);
  const HeadFit fit = fitHead({}, scalp, false);
  size_t inside = 0;
  for (const glm::vec3& p : scalp)
    inside += glm::length((glm::dvec3(p) - fit.centre) / fit.semiAxes) < 1.0 - 1e-6;
  EXPECT_LE(double(inside), kRootsInside * double(scalp.size()) + 1);
  EXPECT_NEAR(fit.centre.y, 1.7, 0.02);
}

const char* kGrouped =
    "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nv 1 1 1\n"
    "g skin\nf 1 2 3\ng scalp\nf 2 5 3\nusemtl hair\nf 1 3 4\n";

TEST(MeshRead, WickGroupKeepsItsFacesAndNamesTheOthersWhenWrong) {
  const Mesh skin = parseObj(kGrouped, "g.obj", MeshReadOptions{"skin", false, {}, {}});
  EXPECT_EQ(skin.triangleCount(), 1u);
  EXPECT_EQ(skin.vertexCount(), 3u);  // only the vertices its faces use
  EXPECT_EQ(parseObj(kGrouped, "g.obj", MeshReadOptions{"scalp", false, {}, {}}).triangleCount(), 2u);
  EXPECT_EQ(parseObj(kGrouped, "g.obj", MeshReadOptions{"hair", false, {}, {}}).triangleCount(), 1u);
  try {
    parseObj(kGrouped, "g.obj", MeshReadOptions{"Scalp", false, {}, {}});
    FAIL() << "a wrong group was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("skin, scalp, hair"), std::string::npos) << e.what();
  }
}

TEST(MeshRead, UnitsAndUpAxisAreAppliedOnReading) {
  UnitConversion cmZUp{0.01, UpAxis::kZ};
  const Mesh m =
      parseObj("v 0 0 0\nv 100 0 0\nv 0 0 100\nf 1 2 3\n", "z.obj", MeshReadOptions{"", false, cmZUp, {}});
  EXPECT_EQ(m.positions[2], glm::vec3(0, 1, 0));  // z-up, centimetres: 1 m up
  EXPECT_NEAR(m.normals[0].z, 1.0f, 1e-6f);       // the file's −y (its normal here) is +z
}

TEST(MeshRead, PointsAloneAreFolliclesFacingAwayFromTheirSphere) {
  std::string text;
  for (const glm::vec3& p : onEllipsoid({0, 1.7, 0}, glm::dvec3(0.1), 0.4))
    text += "v " + std::to_string(p.x) + " " + std::to_string(p.y) + " " + std::to_string(p.z) + "\n";
  EXPECT_THROW(parseObj(text, "roots.obj"), InputError);  // a mesh needs faces unless points are allowed
  const Mesh roots = parseObj(text, "roots.obj", MeshReadOptions{"", true, {}, {}});
  EXPECT_EQ(roots.triangleCount(), 0u);
  for (size_t i = 0; i < roots.vertexCount(); ++i) {
    const glm::vec3 out = glm::normalize(roots.positions[i] - glm::vec3(0, 1.7f, 0));
    EXPECT_GT(glm::dot(out, roots.normals[i]), 0.999f);
  }
}

TEST(SceneCheck, NamesTheUnitsOfAScalpInCentimetres) {
  Config config;
  Mesh scalp;
  scalp.positions = onEllipsoid({0, 170, 0}, glm::dvec3(10), 0.4);  // 10 cm radius, written in cm
  for (int i = 0; i + 41 < int(scalp.positions.size()); ++i)
    if ((i + 1) % 40) scalp.triangles.push_back({uint32_t(i), uint32_t(i + 40), uint32_t(i + 1)});
  const std::vector<SceneFinding> found = checkScene(config, scalp, nullptr);
  ASSERT_FALSE(found.empty());
  EXPECT_TRUE(found[0].refuse);
  EXPECT_NE(found[0].message.find("set MeshUnits cm"), std::string::npos) << found[0].message;
}

// RootFlow away-from auto: the whorl of the head read, behind its top; and the warning for a point made
// for another head names it.
TEST(RootTilt, AwayFromAutoIsTheWhorlOfTheHeadRead) {
  // The scalp a centimetre out from the head's cranium: the whorl is the head's, not the wick's.
  const glm::dvec3 centre(0.0, 1.7, 0.02), axes(0.08, 0.09, 0.11);
  Mesh head, wick;
  head.positions = onEllipsoid(centre, axes, 1.0);
  wick.positions = onEllipsoid(centre, axes + 0.01, 0.4);
  Config config;
  config.hairstyle.rootTilt = 30.0;
  config.hairstyle.rootFlow = {RootFlow::Kind::kAwayFrom, glm::dvec3(0, 0.14, -0.04)};  // the bundled head's
  bool named = false;
  for (const SceneFinding& f : checkScene(config, wick, &head))
    named = named || f.message.find("RootFlow away-from auto") != std::string::npos;
  EXPECT_TRUE(named) << "the warning names away-from auto";
  config.hairstyle.rootFlow.fitted = true;
  EXPECT_THROW(config.hairstyle.growDirection(centre, {0, 1, 0}), std::logic_error) << "not yet found";
  fitRootFlow(config.hairstyle, wick, &head);
  ASSERT_TRUE(config.hairstyle.rootFlow.resolved);
  const glm::dvec3 whorl = config.hairstyle.rootFlow.value;
  const glm::dvec3 expected = centre + axes * glm::dvec3(0.0, 2.0, -1.0) / std::sqrt(5.0);
  EXPECT_LT(glm::length(whorl - expected), 1e-4) << whorl.x << " " << whorl.y << " " << whorl.z;
  EXPECT_GT(glm::length(headWhorl(wick, nullptr) - expected), 0.005) << "the wick's own whorl is further out";
  // A follicle in front of the whorl leans forward, one behind it backward.
  const glm::dvec3 front = centre + axes * glm::dvec3(0, 0.6, 0.8),
                   back = centre + axes * glm::dvec3(0, 0.0, -1.0);
  EXPECT_GT(config.hairstyle.growDirection(front, glm::normalize((front - centre) / (axes * axes))).z,
            glm::normalize((front - centre) / (axes * axes)).z);
  EXPECT_LT(config.hairstyle.growDirection(back, glm::dvec3(0, 0, -1)).y, 0.0);
  // A flat patch fits no head: exit 2 naming what to give instead.
  Mesh patch;
  for (int i = 0; i < 8; ++i)
    for (int j = 0; j < 8; ++j) patch.positions.push_back({0.01f * float(i), 1.7f, 0.01f * float(j)});
  Hairstyle flat = config.hairstyle;
  flat.rootFlow.resolved = false;
  EXPECT_THROW(fitRootFlow(flat, patch, nullptr), InputError);
}

TEST(RootTilt, LeansTheFollicleTowardTheFlowByTheAngle) {
  Hairstyle h;
  const glm::dvec3 n(0, 0, 1);
  EXPECT_EQ(h.growDirection({0, 0, 0}, n), n);  // RootTilt 0: the thesis' normal
  h.rootTilt = 30.0;
  const glm::dvec3 d = h.growDirection({0, 0, 0}, n);  // RootFlow down
  EXPECT_NEAR(glm::degrees(std::acos(glm::dot(d, n))), 30.0, 1e-9);
  EXPECT_LT(d.y, 0.0);
  h.rootFlow = {RootFlow::Kind::kAwayFrom, glm::dvec3(0, 1, 0)};
  EXPECT_EQ(h.growDirection({0, 1, 0}, {0, 1, 0}), glm::dvec3(0, 1, 0));  // at the crown itself: no lean
}

}  // namespace
}  // namespace hairgen
