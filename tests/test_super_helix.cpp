// Super-Helix kinematics and energy: properties the geometry and physics guarantee.
#include <gtest/gtest.h>

#include <random>

#include <glm/gtc/matrix_transform.hpp>

#include "libcore/physics/strand_energy.h"
#include "libcore/physics/super_helix.h"

namespace hairgen {
namespace {

RodFrame verticalRoot() {
  return follicleFrame(glm::dvec3(0.01, 0.2, -0.03), glm::dvec3(0.3, 1.0, 0.2));
}

TEST(SuperHelix, FollicleFrameIsOrthonormalAndUsesUpAsUp) {
  RodFrame f = follicleFrame(glm::dvec3(0.0), glm::dvec3(0.0, 0.0, 2.0));
  EXPECT_NEAR(glm::length(f.n0 - glm::dvec3(0, 0, 1)), 0.0, 1e-15);
  EXPECT_NEAR(glm::length(f.n1 - glm::dvec3(-1, 0, 0)), 0.0, 1e-15);  // n0 × (0,1,0)
  EXPECT_NEAR(glm::dot(f.n1, f.n2), 0.0, 1e-15);
  RodFrame up = follicleFrame(glm::dvec3(0.0), glm::dvec3(0.0, 1.0, 0.0));
  EXPECT_EQ(up.n1, glm::dvec3(0.0, 0.0, 1.0));  // the parallel case falls back to +z
}

TEST(SuperHelix, RestShapeIsTheExactHelix) {
  // A rod at its rest coordinates is a helix of the configured radius and rise per turn.
  const double radius = 0.01, step = 0.05;
  RestShape rest = restShape(radius, step);
  std::vector<double> lengths(4, 0.04), q;
  for (int e = 0; e < 4; ++e) q.insert(q.end(), {rest.tau, rest.kappa1, rest.kappa2});
  RodFrame root = verticalRoot();
  std::vector<double> s = sampleArcLengths(0.16, 0.0005, true);
  std::vector<glm::dvec3> p;
  sampleRod(root, lengths, q, s, p, nullptr);
  // The helix axis is the Darboux vector; distance of every point to the axis is the radius, and the
  // advance along it per turn is the step.
  glm::dvec3 w = darbouxVector(root, rest.tau, rest.kappa1, rest.kappa2);
  glm::dvec3 axis = glm::normalize(w);
  double omega = glm::length(w);
  glm::dvec3 centre =
      root.position + glm::cross(w, root.n0) / (omega * omega);  // axis point, r = 1/Ω² · |W×n0|
  for (size_t i = 0; i < p.size(); ++i) {
    glm::dvec3 v = p[i] - centre;
    glm::dvec3 radial = v - glm::dot(v, axis) * axis;
    EXPECT_NEAR(glm::length(radial), radius, 1e-6 * radius) << "sample " << i;
  }
  double turn = 2.0 * M_PI / omega;  // arc length of one turn
  std::vector<glm::dvec3> ends;
  std::vector<double> two = {0.0, turn};
  sampleRod(root, lengths, q, two, ends, nullptr);
  EXPECT_NEAR(glm::dot(ends[1] - ends[0], axis), step, 1e-6 * step);
}

TEST(SuperHelix, ZeroHelixRadiusMeansStraight) {
  RestShape rest = restShape(0.0, 0.05);
  EXPECT_EQ(rest.kappa1, 0.0);
  EXPECT_EQ(rest.tau, 0.0);
}

TEST(SuperHelix, SampledArcLengthEqualsTotalLength) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> k(-200.0, 200.0);
  std::vector<double> lengths = {0.03, 0.05, 0.02, 0.06}, q;
  for (int i = 0; i < 12; ++i) q.push_back(k(rng));
  std::vector<double> s = sampleArcLengths(0.16, 0.00002, true);
  EXPECT_DOUBLE_EQ(s.back(), 0.16);
  std::vector<glm::dvec3> p;
  sampleRod(verticalRoot(), lengths, q, s, p, nullptr);
  double arc = 0.0;
  for (size_t i = 1; i < p.size(); ++i) arc += glm::length(p[i] - p[i - 1]);
  EXPECT_NEAR(arc, 0.16, 1e-6 * 0.16);
}

TEST(SuperHelix, PositionAndTangentAreContinuousAcrossJoints) {
  std::vector<double> lengths = {0.04, 0.04, 0.04}, q = {50, -80, 120, 0, 300, -10, -90, 5, 60};
  double joints[] = {0.04, 0.08};
  for (double j : joints) {
    std::vector<double> s = {j - 1e-9, j, j + 1e-9};
    std::vector<glm::dvec3> p, t;
    sampleRod(verticalRoot(), lengths, q, s, p, &t);
    EXPECT_NEAR(glm::length(p[2] - p[0]), 2e-9, 1e-12);
    EXPECT_NEAR(glm::length(t[2] - t[0]), 0.0, 1e-6);
  }
}

TEST(SuperHelix, SeriesAndClosedFormAgreeAtTheSwitch) {
  // Just below and above the series threshold the frame must move continuously in κ.
  RodFrame root = verticalRoot();
  double l = 0.04;
  for (double omega : {0.05 / l * 0.999999, 0.05 / l * 1.000001}) {
    RodFrame a = advance(root, omega * root.n1, l);
    RodFrame b = advance(root, 0.05 / l * root.n1, l);
    EXPECT_NEAR(glm::length(a.position - b.position), 0.0, 1e-8);
  }
  RodFrame straight = advance(root, glm::dvec3(0.0), l);
  EXPECT_NEAR(glm::length(straight.position - (root.position + l * root.n0)), 0.0, 1e-18);
}

TEST(StrandEnergy, ClosedFormGravityMatchesQuadrature) {
  // The gravity term of the energy the minimiser calls, ρ S g ∫ (y(s) − y(0)) ds in closed form per
  // element, against Simpson's rule on the sampled centreline.
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> k(-300.0, 300.0);
  Hairstyle style;
  style.hairLengths = {0.04, 0.03, 0.05, 0.04};
  const double weight = style.massDensity * M_PI * style.hairRadius1 * style.hairRadius2 * style.gravity;
  for (int trial = 0; trial < 20; ++trial) {
    std::vector<double> q;
    for (int i = 0; i < 12; ++i) q.push_back(trial == 0 ? 0.0 : k(rng) * (trial % 3 == 0 ? 1e-4 : 1.0));
    RodFrame root = verticalRoot();
    const int n = 20000;
    std::vector<double> s(n + 1);
    for (int i = 0; i <= n; ++i) s[i] = 0.16 * i / n;
    std::vector<glm::dvec3> p;
    sampleRod(root, style.hairLengths, q, s, p, nullptr);
    double sum = 0.0;
    for (int i = 0; i <= n; ++i) sum += (i == 0 || i == n ? 1 : (i % 2 ? 4 : 2)) * (p[i].y - root.position.y);
    double quadrature = weight * sum * (0.16 / n) / 3.0;
    double closed = StrandEnergy(style, Collision{}, root, 0.0).terms(q).gravity;
    EXPECT_NEAR(closed, quadrature, 1e-9 * std::max(std::abs(quadrature), 1e-6 * weight))
        << "trial " << trial;
  }
}

TEST(StrandEnergy, PenetrationFollowsEachShapesDefinition) {
  CollisionShape sphere{ShapeKind::kSphere, 0, 1, glm::dvec3(0), glm::dvec3(0.1), glm::dmat3(1.0), {}};
  EXPECT_NEAR(penetration(sphere, {0.07, 0, 0}), 0.03, 1e-15);
  CollisionShape ellipsoid{ShapeKind::kEllipsoid, 0, 1, glm::dvec3(0), glm::dvec3(0.2, 0.1, 0.1),
                           glm::dmat3(1.0),       {}};
  EXPECT_NEAR(penetration(ellipsoid, {0.1, 0, 0}), 0.1, 1e-15);
  EXPECT_NEAR(penetration(ellipsoid, {0, 0.2, 0}), -0.1, 1e-15);
  CollisionShape cuboid{ShapeKind::kCuboid, 0, 1, glm::dvec3(0), glm::dvec3(0.2, 0.1, 0.3),
                        glm::dmat3(1.0),    {}};
  EXPECT_NEAR(penetration(cuboid, {0.15, 0.02, 0}), 0.05, 1e-15);
}

// An ellipsoid, a sphere and a tilted box where the test strands go, each with an envelope or none.
Collision threeShapes() {
  Collision collision;
  glm::dmat3 tilted = glm::dmat3(glm::rotate(glm::dmat4(1.0), 0.4, glm::dvec3(1, 2, 0.5)));
  collision.shapes = {
      {ShapeKind::kEllipsoid, 0.03, 10.0, glm::dvec3(0, 0.12, 0), glm::dvec3(0.08, 0.1, 0.11), tilted, {}},
      {ShapeKind::kSphere, 0.01, 3.0, glm::dvec3(0.05, 0.2, 0.08), glm::dvec3(0.06), glm::dmat3(1.0), {}},
      {ShapeKind::kCuboid,
       0.0,
       20.0,
       glm::dvec3(-0.04, 0.15, 0.0),
       glm::dvec3(0.05, 0.02, 0.04),
       tilted,
       {}}};
  return collision;
}

TEST(StrandEnergy, CollisionTermEqualsDirectSamplingOfEveryShape) {
  // The energy walks samples by a trigonometric recurrence and rejects far shapes early; it must
  // equal Δs Σ ½k max(penetration + extra, 0)² evaluated point by point from sampleRod.
  Hairstyle style;
  style.hairLengths = {0.035, 0.05, 0.04};  // 0.125 m: the last sample is off the 4 mm grid
  style.collisionStep = 0.004;
  const Collision collision = threeShapes();
  const double envelope = 0.7;
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> k(-60.0, 60.0);
  int touching = 0;
  for (int trial = 0; trial < 20; ++trial) {
    RodFrame root = follicleFrame(glm::dvec3(0.0, 0.2, 0.0), glm::dvec3(0.3 * k(rng) / 60.0, 1.0, 0.2));
    std::vector<double> q;
    for (int i = 0; i < 9; ++i) q.push_back(trial == 0 ? 0.0 : k(rng));
    StrandEnergy energy(style, collision, root, envelope);
    std::vector<double> s = sampleArcLengths(style.totalLength(), style.collisionStep, false);
    std::vector<glm::dvec3> p;
    sampleRod(root, style.hairLengths, q, s, p, nullptr);
    double direct = 0.0;
    for (const glm::dvec3& x : p)
      for (const CollisionShape& shape : collision.shapes) {
        double d = penetration(shape, x) + shape.envelopeGrowth * envelope;
        if (d > 0.0) direct += 0.5 * shape.penalty * d * d;
      }
    direct *= style.collisionStep;
    EXPECT_NEAR(energy.terms(q).collision, direct, 1e-10 * direct + 1e-18) << "trial " << trial;
    touching += direct > 0.0;
  }
  EXPECT_GE(touching, 15);  // the shapes are where the strands go
}

// A box's envelope is the box grown by `extra` on every face: its corners lie beyond the bounding
// sphere's growth, and a straight strand past a grown corner still feels it.
TEST(StrandEnergy, ABoxEnvelopeReachesItsCorners) {
  Hairstyle style;
  style.hairLengths = {0.05};
  style.helixRadius = 0.0;  // straight, up from (0.025, −0.025, 0.025)
  style.collisionStep = 0.002;
  Collision box;
  box.shapes.push_back(
      {ShapeKind::kCuboid, 0.02, 1.0, glm::dvec3(0.0), glm::dvec3(0.01), glm::dmat3(1.0), {}});
  RodFrame root = follicleFrame(glm::dvec3(0.025, -0.025, 0.025), glm::dvec3(0.0, 1.0, 0.0));
  StrandEnergy energy(style, box, root, 1.0);
  const std::vector<double> q = energy.restCoordinates();
  std::vector<glm::dvec3> p;
  sampleRod(root, style.hairLengths, q, sampleArcLengths(0.05, style.collisionStep, false), p, nullptr);
  double direct = 0.0;
  for (const glm::dvec3& x : p) {
    const double d = penetration(box.shapes[0], x) + 0.02;  // each sample 0.035-0.04 m from the centre
    if (d > 0.0) direct += 0.5 * d * d;
  }
  direct *= style.collisionStep;
  ASSERT_GT(direct, 0.0);
  EXPECT_NEAR(energy.terms(q).collision, direct, 1e-12 * direct);
}

TEST(StrandEnergy, GradientMatchesCentralDifferencesAndValueIsTheEnergys) {
  // The gradient of every term (elastic, closed-form gravity, penalties of the three kinds of shape, the
  // series and closed-form branches, a straight element at W = 0) against central differences.
  Hairstyle style;
  style.hairLengths = {0.03, 0.05, 0.04, 0.006};
  style.collisionStep = 0.004;
  style.helixRadius = 0.01;
  style.helixStep = 0.05;
  const Collision collision = threeShapes();
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> k(-60.0, 60.0);
  int touching = 0;
  for (int trial = 0; trial < 20; ++trial) {
    RodFrame root = follicleFrame(glm::dvec3(0.0, 0.2, 0.0), glm::dvec3(0.3 * k(rng) / 60.0, 1.0, 0.2));
    StrandEnergy energy(style, collision, root, 0.6);
    std::vector<double> q;
    for (int i = 0; i < 12; ++i) q.push_back(k(rng));
    if (trial == 0) std::fill(q.begin(), q.end(), 0.0);  // straight: W = 0 in every element
    if (trial == 1) q[9] = 0.5, q[10] = q[11] = 0.0;     // Ω ℓ = 0.003: the series
    std::vector<double> gradient(q.size());
    const double value = energy.valueAndGradient(q, gradient);
    EXPECT_EQ(value, energy(q)) << "trial " << trial;
    touching += energy.terms(q).collision > 0.0;
    for (size_t i = 0; i < q.size(); ++i) {
      const double h = 1e-4;
      std::vector<double> up = q, down = q;
      up[i] += h;
      down[i] -= h;
      const double central = (energy(up) - energy(down)) / (2.0 * h);
      EXPECT_NEAR(gradient[i], central, 1e-5 * std::abs(central) + 1e-14)
          << "trial " << trial << ", coordinate " << i;
    }
  }
  EXPECT_GE(touching, 10);
}

}  // namespace
}  // namespace hairgen
