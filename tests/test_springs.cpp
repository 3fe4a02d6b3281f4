// Model springs (libcore/physics/spring_dynamics, Petrovic et al. 2006 §5): a hanging chain and a
// clamped cantilever ring at their continuum frequencies; the groomed coupe holds its shape; velocity
// smoothing only ever removes kinetic energy; density targeting pulls the hair toward a target's
// density; threads and restarts change no bit.
#include <gtest/gtest.h>

#include <tbb/global_control.h>
#include <algorithm>
#include <cmath>
#include <cstring>
#include <functional>
#include <optional>
#include <random>

#include "libcore/config/setup.h"
#include "libcore/io/hair_cache.h"
#include "libcore/io/restart_state.h"
#include "libcore/physics/head_motion.h"
#include "libcore/physics/spring_dynamics.h"
#include "libcore/util/cpu.h"
#include "stages/grow.h"
#include "stages/simulate.h"
#include "tests/test_util.h"

namespace hairgen {
namespace {

// One strand of `segments` equal segments from `root` along `dir`, `length` long.
std::vector<glm::vec3> straight(const glm::dvec3& root, const glm::dvec3& dir, double length, int segments) {
  std::vector<glm::vec3> points;
  for (int i = 0; i <= segments; ++i) points.push_back(glm::vec3(root + dir * (length * i / segments)));
  return points;
}

Dynamics springs() {
  Dynamics d;
  d.given = true;
  d.model = DynamicsModel::kSprings;
  d.damping = 0.0;
  return d;
}

double meanPeriod(const std::vector<double>& crossings) {
  return (crossings.back() - crossings.front()) / double(crossings.size() - 1);
}

// A heavy chain with no bending, hanging from its root, swings at ω = 1.2024 sqrt(g/L) (the first zero
// of J0 over 2); started in its continuum mode shape J0(2.405 sqrt(s/L)), s from the free end.
TEST(Springs, AHangingChainSwingsAtTheContinuumFundamental) {
  const double length = 0.3, g = 9.81, dt = 1e-3;
  const int segments = 32;
  Strands rest;
  rest.addStrand(straight({0, 0, 0}, {0, -1, 0}, length, segments));
  Hairstyle style;
  style.gravity = g;
  Dynamics d = springs();
  d.bendStiffnessAuto = d.twistStiffnessAuto = false;
  d.bendStiffness = d.twistStiffness = 0.0;
  SpringHair hair(rest, style, d, Collision{}, nullptr);
  std::vector<glm::dvec3> x = hair.positions();
  for (int i = 0; i <= segments; ++i) {
    const double s = length * (1.0 - double(i) / segments);
    x[size_t(i)].x += 1e-3 * length * std::cyl_bessel_j(0.0, 2.405 * std::sqrt(s / length));
  }
  x[0].x = 0.0;
  hair.setPositions(x);
  AccelerationField field;
  field.base = {0.0, -g, 0.0};
  std::vector<double> tip;
  const double expected = 2.0 * M_PI / (1.2024 * std::sqrt(g / length));
  for (int n = 0; n < int(10.5 * expected / dt); ++n) {
    hair.step(field, dt, true, false);
    tip.push_back(hair.positions()[size_t(segments)].x);
  }
  const std::vector<double> crossings = test::downCrossings(tip, dt);
  ASSERT_GE(crossings.size(), 9u);
  const double period = meanPeriod(crossings);
  EXPECT_NEAR(period / expected, 1.0, 0.02) << "period " << period << " s, continuum " << expected << " s";
  RecordProperty("period_ratio", std::to_string(period / expected));
  EXPECT_LT(hair.maxStretch(), 1e-4);
}

// A straight hair clamped horizontal, no gravity, bent into its first mode and let go: it rings at
// (1.875²) sqrt(E I / (ρ A L⁴)).
TEST(Springs, AClampedCantileverRingsAtItsFirstMode) {
  const double length = 0.1, dt = 1e-3;
  const int segments = 31;  // 32 particles
  Strands rest;
  rest.addStrand(straight({0, 0, 0}, {1, 0, 0}, length, segments));
  Hairstyle style;
  style.gravity = 0.0;
  const Dynamics d = springs();
  SpringHair hair(rest, style, d, Collision{}, nullptr);
  const SpringStiffness k = springStiffness(style, d);
  const double lineDensity = style.massDensity * M_PI * style.hairRadius1 * style.hairRadius2;
  const double omega = 1.875 * 1.875 * std::sqrt(k.bend / (lineDensity * std::pow(length, 4)));
  // The first mode's shape, β L = 1.8751.
  const double bl = 1.8751, sigma = (std::cosh(bl) + std::cos(bl)) / (std::sinh(bl) + std::sin(bl));
  std::vector<glm::dvec3> x = hair.positions();
  for (int i = 1; i <= segments; ++i) {
    const double b = bl * double(i) / segments;
    x[size_t(i)].y +=
        1e-3 * length * (std::cosh(b) - std::cos(b) - sigma * (std::sinh(b) - std::sin(b))) / 2.0;
  }
  hair.setPositions(x);
  std::vector<double> tip;
  const double expected = 2.0 * M_PI / omega;
  for (int n = 0; n < int(6.5 * expected / dt); ++n) {
    hair.step(AccelerationField{}, dt, true, false);
    tip.push_back(hair.positions()[size_t(segments)].y);
  }
  const std::vector<double> crossings = test::downCrossings(tip, dt);
  ASSERT_GE(crossings.size(), 5u);
  const double period = meanPeriod(crossings);
  EXPECT_NEAR(period / expected, 1.0, 0.05) << "period " << period << " s, beam theory " << expected << " s";
  RecordProperty("period_ratio", std::to_string(period / expected));
}

// A curved hair reaching out sideways under gravity: the sag-free rest holds it exactly where it was
// groomed, though its bending stiffness alone would let it droop by centimetres.
TEST(Springs, ACurvedHairHoldsItsGroomedShapeUnderGravity) {
  Strands rest;
  std::vector<glm::vec3> points;
  for (int i = 0; i <= 10; ++i) points.push_back(glm::vec3(0.01f * i, 0.0002f * i * i, 0.0f));
  rest.addStrand(points);
  const Hairstyle style;
  const Dynamics d = springs();
  SpringHair hair(rest, style, d, Collision{}, nullptr);
  AccelerationField field;
  field.base = {0.0, -style.gravity, 0.0};
  auto worst = [&] {
    double w = 0.0;
    for (size_t p = 0; p < points.size(); ++p)
      w = std::max(w, glm::length(hair.positions()[p] - glm::dvec3(points[p])));
    return w;
  };
  for (int n = 0; n < 100; ++n) hair.step(field, 1e-2, true, false);
  EXPECT_LT(worst(), 1e-9);
  // Twice the gravity it was groomed under: it droops.
  field.base *= 2.0;
  for (int n = 0; n < 100; ++n) hair.step(field, 1e-2, true, false);
  EXPECT_GT(worst(), 1e-3);
}

// The substep in vectors (8 strands at once, on AVX-512) gives the strand-by-strand step's bits, and so
// does the posing, eight points at a time: strands of 1 to 12 points (a block of 8 with mixed counts,
// some stepped in lanes, some alone, and 14 strands, not a whole number of blocks), one of 140 segments
// (past the lanes' limit, first in its block, so the lanes are the next strand's), pushed hard into an
// ellipsoid, a sphere and a box (so the collisions and the second solve run) while the head turns.
TEST(Springs, EveryKernelGivesTheSameBits) {
  if (!hasAvx512()) GTEST_SKIP() << "no AVX-512 here: the vector kernel cannot run, only the strands' does";
  const Collision shapes = test::kernelShapes();
  std::vector<int> counts;
  for (int s = 0; s < 14; ++s) counts.push_back(s == 8 ? 141 : s == 5 ? 1 : s < 8 ? 2 + (s * 5) % 11 : 9);
  const Strands rest = test::kernelHair(counts);
  Hairstyle style;
  style.gravity = 9.81;
  Dynamics d = springs();
  d.damping = 0.5;
  const AccelerationField field = test::kernelField();
  using Kernel = SpringHair::Kernel;
  Pose turned;  // the posed output too, moved and turned as a head that looks aside
  turned.rotation = eulerRotation({10.0, 35.0, -5.0});
  turned.translation = {0.01, -0.02, 0.03};
  turned.centre = {0.0, 0.1, 0.0};
  auto run = [&](Kernel kernel) {
    SpringHair hair(rest, style, d, shapes, nullptr);
    for (int n = 0; n < 40; ++n) hair.step(field, 1.0 / 96.0, n % 2 == 0, n % 2 == 1, kernel);
    Strands still, posed;
    hair.posedInto(Pose{}, still, kernel);
    hair.posedInto(turned, posed, kernel);
    return std::tuple(hair.positions(), hair.velocities(), still, posed, hair.state());
  };
  const auto [x, v, still, posed, state] = run(Kernel::kStrands);
  double deepest = -1.0;
  for (const glm::dvec3& p : x) deepest = std::max(deepest, penetration(shapes.shapes[0], p));
  EXPECT_GT(deepest, -1e-3) << "the hair must reach the head";
  for (Kernel kernel : {Kernel::kLanes, Kernel::kFastest}) {  // the strands' again without AVX-512
    const auto [xk, vk, stillk, posedk, statek] = run(kernel);
    // The whole restart state: the step's history (v⁻, the last move) too.
    ASSERT_EQ(statek.size(), state.size());
    ASSERT_EQ(0, std::memcmp(statek.data(), state.data(), state.size() * sizeof(double)));
    ASSERT_EQ(xk.size(), x.size());
    for (size_t p = 0; p < x.size(); ++p) {
      ASSERT_EQ(0, std::memcmp(&xk[p], &x[p], sizeof(glm::dvec3))) << "position of point " << p;
      ASSERT_EQ(0, std::memcmp(&vk[p], &v[p], sizeof(glm::dvec3))) << "velocity of point " << p;
    }
    for (const auto& [a, b] : {std::pair(&stillk, &still), std::pair(&posedk, &posed)}) {
      ASSERT_EQ(a->points.size(), x.size());
      ASSERT_EQ(0, std::memcmp(a->points.data(), b->points.data(), x.size() * sizeof(glm::vec3)));
      ASSERT_EQ(0, std::memcmp(a->tangents.data(), b->tangents.data(), x.size() * sizeof(glm::vec3)));
    }
  }
}

// The same on curled hair, whose twist springs act (planar strands have none): two full blocks of
// helices of 20 points hanging from around the crown, one rooted at −0 in x and z (a root never moves,
// so its bits stay), and the same hair drawn toward a density target, whose forces are read strand by
// strand before the stretch solve in lanes.
TEST(Springs, EveryKernelGivesTheSameBitsOnCurls) {
  if (!hasAvx512()) GTEST_SKIP() << "no AVX-512 here: the vector kernel cannot run, only the strands' does";
  Strands rest, target;
  for (int s = 0; s < 16; ++s) {
    const double around = glm::radians(22.5 * s);
    const glm::dvec3 root = s == 0 ? glm::dvec3(-0.0, 0.125, -0.0)
                                   : glm::dvec3(0.05 * std::cos(around), 0.115, 0.05 * std::sin(around));
    std::vector<glm::vec3> points, shifted;
    for (int j = 0; j < 20; ++j) {
      const double turn = 0.9 * j + around;
      const glm::dvec3 p =
          root + glm::dvec3(0.008 * (std::cos(turn) - std::cos(around)) + 0.004 * j * std::cos(around),
                            -0.006 * j,
                            0.008 * (std::sin(turn) - std::sin(around)) + 0.004 * j * std::sin(around));
      points.push_back(glm::vec3(j == 0 ? root : p));  // (−0 + 0 would be +0)
      shifted.push_back(glm::vec3(p + glm::dvec3(0.03, 0.0, 0.0) * (double(j) / 19.0)));
    }
    rest.addStrand(points);
    target.addStrand(shifted);
  }
  ASSERT_TRUE(std::signbit(rest.points[0].x) && std::signbit(rest.points[0].z));
  Hairstyle style;
  style.gravity = 9.81;
  const AccelerationField field = test::kernelField();
  using Kernel = SpringHair::Kernel;
  for (const bool density : {false, true}) {
    Dynamics d = springs();
    d.damping = 0.5;
    if (density) {
      d.densityStrength = 5.0;
      d.densitySpacings = {0.01};
    }
    auto run = [&](Kernel kernel, bool* twisted) {
      SpringHair hair(rest, style, d, test::kernelShapes(), density ? &target : nullptr);
      const std::vector<glm::dvec3> start = hair.positions();
      for (int n = 0; n < 40; ++n) hair.step(field, 1.0 / 96.0, n % 2 == 0, n % 2 == 1, kernel);
      if (twisted) *twisted = hair.positions() != start;
      return std::tuple(hair.positions(), hair.velocities(), hair.state());
    };
    bool moved = false;
    const auto [x, v, state] = run(Kernel::kStrands, &moved);
    EXPECT_TRUE(moved);
    const auto [xk, vk, statek] = run(Kernel::kLanes, nullptr);
    ASSERT_EQ(statek.size(), state.size());
    ASSERT_EQ(0, std::memcmp(statek.data(), state.data(), state.size() * sizeof(double)))
        << "the restart state" << (density ? " (density)" : "");
    ASSERT_EQ(xk.size(), x.size());
    for (size_t p = 0; p < x.size(); ++p) {
      ASSERT_EQ(0, std::memcmp(&xk[p], &x[p], sizeof(glm::dvec3)))
          << "position of point " << p << (density ? " (density)" : "");
      ASSERT_EQ(0, std::memcmp(&vk[p], &v[p], sizeof(glm::dvec3)))
          << "velocity of point " << p << (density ? " (density)" : "");
    }
    EXPECT_TRUE(std::signbit(x[0].x) && std::signbit(x[0].z)) << "the root at −0 stays there";
  }
}

// A job on the bundled default coupe with a springs Dynamics Info in memory.
Config springJob(const std::vector<HeadKey>& keys, const std::vector<WindKey>& wind, int last) {
  Config config = test::loadJob("default/setup.txt").config;
  config.dynamics = springs();
  config.dynamics.damping = 1.0;
  config.dynamics.substeps = 4;
  config.dynamics.lastFrame = last;
  config.dynamics.headKeys = keys;
  config.dynamics.wind = wind;
  return config;
}

SimulateOptions frames(const Config& config, FrameRange range, const Strands* restart = nullptr) {
  SimulateOptions options;
  options.configDigest = config.digest();
  options.frames = range;
  options.restart = restart;
  options.restartName = "restart";
  return options;
}

Strands someGuides(const Config& config, size_t every) {
  const Mesh wick = test::loadJob("default/setup.txt").wick;
  Mesh few = wick;
  few.positions.clear();
  few.normals.clear();
  for (size_t i = 0; i < wick.vertexCount(); i += every) {
    few.positions.push_back(wick.positions[i]);
    few.normals.push_back(wick.normals[i]);
  }
  few.triangles.clear();
  return grow(few, config.hairstyle, config.collision, GrowOptions{}).guides;
}

// DESIGN §2: gravity acts on moving hair. A hanging chain with no bending swings at ω = 1.2024 sqrt(g/L)
// (above): through the simulate stage, set by the Gravity keys a TD writes, a steady side wind sets a
// 30 cm chain swinging, and its period shortens by sqrt(30/9.81) when Gravity is 30 instead of 9.81,
// whether Dynamics Gravity or Hairstyle Gravity says so.
TEST(Springs, GravitySetsTheSwingPeriodOfHangingHair) {
  const double length = 0.3;
  Strands rest;
  rest.addStrand(straight({0, 0, 0}, {0, -1, 0}, length, 16));
  auto period = [&](double hairstyleGravity, std::optional<double> dynamicsGravity) {
    Config config = springJob({}, {{1, {0.2, 0.0, 0.0}, false, {}}}, 400);
    config.collision = Collision{};
    config.dynamics.damping = 0.0;
    config.dynamics.frameRate = 100.0;
    config.dynamics.bendStiffnessAuto = config.dynamics.twistStiffnessAuto = false;
    config.dynamics.bendStiffness = config.dynamics.twistStiffness = 0.0;
    config.hairstyle.gravity = hairstyleGravity;
    config.dynamics.gravityAuto = !dynamicsGravity;
    config.dynamics.gravity = dynamicsGravity.value_or(0.0);
    std::vector<double> tip;
    simulate(rest, config, frames(config, {1, 400}),
             [&](int, const Strands& guides) { tip.push_back(guides.points.back().x); });
    double mean = 0.0;
    for (double x : tip) mean += x / double(tip.size());
    for (double& x : tip) x -= mean;
    const std::vector<double> crossings = test::downCrossings(tip, 1.0 / config.dynamics.frameRate);
    EXPECT_GE(crossings.size(), 4u);
    return crossings.size() < 2 ? 0.0 : meanPeriod(crossings);
  };
  const double earth = period(9.81, std::nullopt), heavy = period(9.81, 30.0), heavyStyle = period(30.0, {});
  const double continuum = 2.0 * M_PI / (1.2024 * std::sqrt(9.81 / length));
  EXPECT_NEAR(earth / continuum, 1.0, 0.03) << "period " << earth << " s, continuum " << continuum << " s";
  EXPECT_NEAR(earth / heavy, std::sqrt(30.0 / 9.81), 0.02 * std::sqrt(30.0 / 9.81))
      << earth << " s, " << heavy;
  EXPECT_NEAR(heavyStyle / heavy, 1.0, 1e-3);
  RecordProperty("period_9_81", std::to_string(earth));
  RecordProperty("period_30", std::to_string(heavy));
}

TEST(Springs, TheGroomedCoupeDoesNotSag) {
  Config config = springJob({}, {}, 240);
  const Strands rest = someGuides(config, 3);
  double worst = 0.0;
  simulate(rest, config, frames(config, {1, 240}), [&](int, const Strands& guides) {
    for (size_t p = 0; p < rest.pointCount(); ++p)
      worst = std::max(worst, double(glm::length(guides.points[p] - rest.points[p])));
  });
  EXPECT_LT(worst, 1e-3) << "a vertex moved " << worst * 1e3 << " mm";
  RecordProperty("worst_mm", std::to_string(worst * 1e3));
}

// Two locks of parallel hairs, no gravity, driven through each other.
struct Locks {
  Strands rest;
  size_t perLock = 0;
  Locks() {
    for (int lock = 0; lock < 2; ++lock)
      for (int i = 0; i < 6; ++i)
        for (int j = 0; j < 6; ++j) {
          const glm::dvec3 root(lock * 0.02 + 0.002 * i, 0.0, 0.002 * j);
          rest.addStrand(straight(root, {0, -1, 0}, 0.1, 16));
        }
    perLock = rest.strandCount() / 2;
  }
};

// The spread of velocities across a lock: at each point index along the hairs, the RMS departure of
// the lock's hairs from their mean there (what a root-fixed swing does not contribute to).
double spread(const SpringHair& hair, const Strands& rest, size_t from, size_t to) {
  const uint32_t points = rest.pointsOf(from);
  double sum = 0.0;
  for (uint32_t k = 1; k < points; ++k) {
    glm::dvec3 mean(0.0);
    for (size_t s = from; s < to; ++s) mean += hair.velocities()[rest.firstPoint[s] + k];
    mean /= double(to - from);
    for (size_t s = from; s < to; ++s) {
      const glm::dvec3 d = hair.velocities()[rest.firstPoint[s] + k] - mean;
      sum += glm::dot(d, d);
    }
  }
  return std::sqrt(sum / double((points - 1) * (to - from)));
}

TEST(Springs, VelocitySmoothingNeverAddsKineticEnergy) {
  const Locks locks;
  Hairstyle style;
  style.gravity = 0.0;
  Dynamics d = springs();
  d.smoothingSpacing = 0.005;
  // Random velocities: whatever they are, smoothing keeps or lowers the kinetic energy.
  {
    SpringHair hair(locks.rest, style, d, Collision{}, nullptr);
    std::mt19937_64 random(7);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    for (int trial = 0; trial < 20; ++trial) {
      for (size_t p = 0; p < hair.velocities().size(); ++p)
        if (hair.masses()[p] > 0.0 && p % 17 != 0)
          hair.velocities()[p] = glm::dvec3(u(random), u(random), u(random));
      for (double s : {0.1, 0.5, 1.0}) {
        const double before = hair.kineticEnergy();
        hair.smoothVelocities(s);
        EXPECT_LE(hair.kineticEnergy(), before * (1.0 + 1e-12)) << "trial " << trial << ", s " << s;
      }
    }
  }
  // The two locks driven through each other at ±1 m/s across, with a spread of their own: every step's
  // smoothing lowers the energy, and the spread in a lock ends lower than without smoothing.
  auto drive = [&](double s, bool check) {
    SpringHair hair(locks.rest, style, d, Collision{}, nullptr);
    std::mt19937_64 random(3);
    std::uniform_real_distribution<double> u(-0.2, 0.2);
    std::vector<glm::dvec3> motion(hair.velocities().size(), glm::dvec3(0.0));
    for (size_t strand = 0; strand < locks.rest.strandCount(); ++strand) {
      const glm::dvec3 v(strand < locks.perLock ? 1.0 : -1.0, 0.0, 0.0);
      const glm::dvec3 own = v + glm::dvec3(u(random), 0.0, u(random));
      for (uint32_t p = locks.rest.firstPoint[strand] + 1; p < locks.rest.firstPoint[strand + 1]; ++p)
        motion[p] = own;
    }
    hair.setMotion(motion);  // a motion that has gone on: BDF2's history the same
    int raised = 0;
    for (int n = 0; n < 60; ++n) {
      hair.step(AccelerationField{}, 1.0 / 240.0, true, false);
      const double before = hair.kineticEnergy();
      hair.smoothVelocities(s);
      if (check && hair.kineticEnergy() > before * (1.0 + 1e-12)) ++raised;
    }
    EXPECT_EQ(raised, 0);
    return spread(hair, locks.rest, 0, locks.perLock);
  };
  const double smooth = drive(0.3, true), free = drive(0.0, false);
  EXPECT_LT(smooth, 0.8 * free) << "spread " << smooth << " m/s smoothed, " << free << " m/s without";
  RecordProperty("spread_ratio", std::to_string(smooth / free));
}

// Density targeting on a small fan of hairs, no gravity, damped: from straight down toward the same
// hairs swung 25° about their roots.
struct Targeting {
  Strands rest, target;
  Hairstyle style;
  Dynamics d = springs();
  Targeting() {
    for (int i = 0; i < 10; ++i)
      for (int j = 0; j < 10; ++j) {
        const glm::dvec3 root(0.003 * i, 0.0, 0.003 * j);
        rest.addStrand(straight(root, {0, -1, 0}, 0.1, 16));
        const double a = glm::radians(25.0);
        target.addStrand(straight(root, {std::sin(a), -std::cos(a), 0}, 0.1, 16));
      }
    style.gravity = 0.0;
    d.damping = 20.0;
    d.densityStrength = 5.0;
    d.densitySpacings = {0.01};
  }
};

TEST(Springs, DensityTargetingLowersTheEnergyMonotonically) {
  Targeting t;
  SpringHair hair(t.rest, t.style, t.d, Collision{}, &t.target);
  const double start = hair.densityEnergy(0);
  double previous = start;
  int rises = 0;
  for (int frame = 0; frame < 96; ++frame) {
    for (int s = 0; s < 4; ++s) hair.step(AccelerationField{}, 1.0 / 96.0, s == 0, s == 3);
    const double e = hair.densityEnergy(0);
    // Settled, E wobbles by up to 4e-4 of its start as points cross grid lines (the force jumps there,
    // and the step keeps what it excites but for the damping): a rise is more.
    if (e > previous + 5e-4 * start) ++rises;
    previous = e;
  }
  EXPECT_EQ(rises, 0);
  EXPECT_LT(previous, 0.2 * start) << "E from " << start << " to " << previous;
  RecordProperty("energy_ratio", std::to_string(previous / start));
  EXPECT_LT(hair.maxStretch(), 0.01);
}

TEST(Springs, DensityStrengthZeroMovesNothing) {
  Targeting t;
  t.d.densityStrength = 0.0;
  SpringHair hair(t.rest, t.style, t.d, Collision{}, &t.target);
  const std::vector<glm::dvec3> start = hair.positions();
  for (int n = 0; n < 40; ++n) hair.step(AccelerationField{}, 1.0 / 96.0, n % 4 == 0, n % 4 == 3);
  EXPECT_TRUE(hair.positions() == start);
}

TEST(Springs, ThreadsAndRestartsChangeNoBit) {
  HeadKey start, turned;
  turned.frame = 10;
  turned.rotation = {0.0, 60.0, 0.0};
  Config config = springJob({start, turned}, {{3, {-8.0, 0.0, 2.0}, true, {}}}, 16);
  config.dynamics.velocitySmoothing = 0.3;
  const Strands rest = someGuides(config, 13);
  auto run = [&](size_t threads, FrameRange range, const Strands* restart) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
    std::vector<Strands> out;
    simulate(rest, config, frames(config, range, restart),
             [&](int, const Strands& guides) { out.push_back(guides); });
    return out;
  };
  const std::vector<Strands> one = run(1, {1, 16}, nullptr);
  EXPECT_FALSE(one.front().points == one.back().points);  // it moved
  EXPECT_TRUE(one == run(2, {1, 16}, nullptr));
  EXPECT_TRUE(one == run(4, {1, 16}, nullptr));
  const std::vector<Strands> second = run(2, {9, 16}, &one[7]);  // resumed from frame 8
  ASSERT_EQ(second.size(), 8u);
  for (size_t i = 0; i < 8; ++i) EXPECT_TRUE(second[i] == one[8 + i]) << "frame " << 9 + i;
}

// A restart state is an input: every state a simulation could not have written is refused before a step
// (a position 1e200 m or 1e30 m away crashed the process or resumed into strands 1e16 m long), and so is
// the state of other rest guides with the same strand layout, or of a hairgen that did not record them.
// restart_state.h's bounds on one segment of 1 cm, the rule the step and a restart both apply: within
// kMaxSpringStretch (1%) of its rest length, slower than kMaxSpringSpeed, finite; checked in that order.
TEST(Springs, ASegmentsBoundsAreItsStretchSpeedAndFiniteness) {
  const glm::dvec3 root(0.0), still(0.0);
  const double rest = 0.01;
  auto at = [&](double length) { return glm::dvec3(0.0, -length, 0.0); };
  EXPECT_FALSE(springSegmentFault(root, at(0.0100999), glm::dvec3(999.0, 0.0, 0.0), rest));
  EXPECT_FALSE(springSegmentFault(root, at(0.0099001), still, rest));
  const auto stretched = springSegmentFault(root, at(0.0102), glm::dvec3(2000.0, 0.0, 0.0), rest);
  ASSERT_TRUE(stretched);
  EXPECT_EQ(stretched->kind, SpringSegmentFault::kStretch);  // before the speed
  EXPECT_NEAR(stretched->value, 0.02, 1e-12);
  const auto squeezed = springSegmentFault(root, at(0.0098), still, rest);
  ASSERT_TRUE(squeezed);
  EXPECT_NEAR(squeezed->value, -0.02, 1e-12);
  const auto fast = springSegmentFault(root, at(rest), glm::dvec3(0.0, 0.0, -1001.0), rest);
  ASSERT_TRUE(fast);
  EXPECT_EQ(fast->kind, SpringSegmentFault::kSpeed);
  EXPECT_DOUBLE_EQ(fast->value, 1001.0);
  const auto nan = springSegmentFault(root, at(0.02), glm::dvec3(std::nan(""), 0.0, 0.0), rest);
  ASSERT_TRUE(nan);
  EXPECT_EQ(nan->kind, SpringSegmentFault::kNotFinite);  // before the stretch
}

// The step's history (a velocity a substep before, a move over a substep) is bounded as a velocity is.
TEST(Springs, TheHistorysBoundsAreTheVelocitys) {
  EXPECT_FALSE(springSpeedFault(glm::dvec3(0.0, 999.0, 0.0)));
  const auto fast = springSpeedFault(glm::dvec3(600.0, 0.0, -800.1));
  ASSERT_TRUE(fast);
  EXPECT_EQ(fast->kind, SpringSegmentFault::kSpeed);
  EXPECT_NEAR(fast->value, 1000.08, 1e-2);
  const auto infinite = springSpeedFault(glm::dvec3(0.0, 0.0, INFINITY));
  ASSERT_TRUE(infinite);
  EXPECT_EQ(infinite->kind, SpringSegmentFault::kNotFinite);
}

TEST(Springs, ARestartStateNoSimulationWritesIsRefused) {
  HeadKey start, turned;
  turned.frame = 6;
  turned.rotation = {0.0, 40.0, 0.0};
  const Config config = springJob({start, turned}, {}, 8);
  const Strands rest = someGuides(config, 13);
  std::vector<Strands> one;
  simulate(rest, config, frames(config, {1, 4}), [&](int, const Strands& guides) { one.push_back(guides); });
  const Strands& frame4 = one.back();
  auto resume = [&](const Strands& restGuides, const Strands& cache) {
    int written = 0;
    simulate(restGuides, config, frames(config, {5, 8}, &cache), [&](int, const Strands&) { ++written; });
    return written;
  };
  EXPECT_EQ(resume(rest, frame4), 4);
  const size_t n = frame4.simulationState.size();
  const double nan = std::nan("");
  // The last segment's values: position, velocity, the velocity a substep before, the last move.
  const size_t last = n - kSpringStateValues;
  for (auto spoil : std::vector<std::function<void(Strands&)>>{
           [](Strands& c) { c.simulationState[0] = 1e200; },          // a position far away
           [](Strands& c) { c.simulationState[1] = 1e30; },           // not so far
           [&](Strands& c) { c.simulationState[last + 3] = nan; },    // a velocity that is no number
           [&](Strands& c) { c.simulationState[last + 4] = 1e5; },    // a velocity past any hair's
           [&](Strands& c) { c.simulationState[last + 8] = 1e5; },    // and the one a substep before
           [&](Strands& c) { c.simulationState[last + 9] = nan; },    // a last move that is no number
           [&](Strands& c) { c.simulationState[last + 11] = -1e5; },  // or past any hair's speed
           [&](Strands& c) { c.simulationState[last] += 1e-2; },      // the last tip 1 cm off
           [&](Strands& c) { c.simulationState.resize(n - kSpringStateValues); },  // a segment short
           [](Strands& c) { c.provenance.restDigest.clear(); }}) {                 // an older hairgen's
    Strands spoiled = frame4;
    spoil(spoiled);
    EXPECT_THROW(resume(rest, spoiled), InputError);
  }
  // An older hairgen's 6 values a segment (before the BDF2 step) is named as such.
  Strands older = frame4;
  older.simulationState.resize(n / 2);
  try {
    resume(rest, older);
    ADD_FAILURE() << "resumed from a 6-value state";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("layout of an earlier hairgen"), std::string::npos) << e.what();
  }
  // Other rest guides with the same strand layout: one point moved by a tenth of a millimetre.
  Strands other = rest;
  other.points[other.firstPoint[1] + 2].x += 1e-4f;
  try {
    resume(other, frame4);
    ADD_FAILURE() << "resumed from the state of other rest guides";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("other rest guides"), std::string::npos) << e.what();
  }
}

// DESIGN §2: a simulation that leaves its validity stops with an error, never a frame of nonsense. A
// wind of 100 m/s² at one frame a second stretched the hair by a quarter with exit 0; now the frame it
// happens at is not delivered, the ones before are, and the error names the wind, the step's keys,
// the frame and the strand. Every frame delivered is a state a restart accepts.
TEST(Springs, AStepThatLeavesItsValidityStopsNamingKeyFrameAndStrand) {
  Config config = springJob({}, {{1, {100.0, 0.0, 0.0}, false, {}}}, 12);
  config.dynamics.frameRate = 1.0;
  const Strands rest = someGuides(config, 13);
  std::vector<int> delivered;
  try {
    simulate(rest, config, frames(config, {1, 12}), [&](int frame, const Strands& guides) {
      delivered.push_back(frame);
      EXPECT_NO_THROW(checkStateValues(rest, guides.simulationState, DynamicsModel::kSprings, "frame"));
    });
    ADD_FAILURE() << "a quarter's stretch was delivered as hair";
  } catch (const SimulationDiverged& e) {
    const std::string message = e.what();
    for (const char* word : {"Dynamics.Wind 100", "Dynamics.FrameRate 1", "Dynamics.Substeps", "strand "})
      EXPECT_NE(message.find(word), std::string::npos) << word << " in: " << message;
    ASSERT_FALSE(delivered.empty());
    EXPECT_NE(message.find("frame " + std::to_string(delivered.back() + 1) + ":"), std::string::npos)
        << message;
    EXPECT_EQ(e.code(), ExitCode::kBadInput);
  }
}

// The bundled springs shots run to their last frame at their own substeps (4), and their hair keeps near
// the shape it takes at 64: over a fifth of the coupe's guides (152), on every frame, the median guide's
// largest joint turn is within 12° of its value at 64 substeps, and the 95th percentile guide's within
// 45°. Measured: 3.7° and 36° (wind), 7.0° and 12.6° (head turn), 8.7° and 16.6° (without smoothing);
// the largest turns at 64 substeps are 11-14°, the groom's own curl 9.5°. What remains is the stretch
// projection's splitting (docs/dynamics-springs.md). Before the BDF2 step, on all 759 guides:
// configs/pixar/wind stopped at frame 6 with a segment 1% off its rest length, and the head turns were
// 46° and 56° off in the median (their median guide's largest turn up to 55° and 65°): the locks kinked.
TEST(Springs, TheBundledSpringShotsRunToTheEndAsAtManySubsteps) {
  auto largestTurns = [](const Strands& hair) {
    std::vector<double> out;
    for (size_t s = 0; s < hair.strandCount(); ++s) {
      double largest = 0.0;
      for (uint32_t p = hair.firstPoint[s] + 1; p + 1 < hair.firstPoint[s] + hair.pointsOf(s); ++p) {
        const glm::dvec3 a = glm::normalize(glm::dvec3(hair.points[p] - hair.points[p - 1]));
        const glm::dvec3 b = glm::normalize(glm::dvec3(hair.points[p + 1] - hair.points[p]));
        largest = std::max(largest, glm::degrees(std::acos(std::clamp(glm::dot(a, b), -1.0, 1.0))));
      }
      out.push_back(largest);
    }
    std::sort(out.begin(), out.end());
    return out;
  };
  auto at = [](const std::vector<double>& sorted, double q) {
    return sorted[size_t(q * double(sorted.size() - 1))];
  };
  for (const char* shot :
       {"pixar/wind/setup.txt", "pixar/headturn/setup.txt", "pixar/headturn-nosmooth/setup.txt"}) {
    Config config = test::loadJob(shot).config;
    const Strands rest = someGuides(config, 5);
    // Per frame the median and 95th percentile guides' largest turns, at the shot's substeps and at 64.
    auto run = [&](int substeps) {
      config.dynamics.substeps = substeps;
      std::vector<std::pair<double, double>> out;
      EXPECT_NO_THROW(simulate(rest, config,
                               frames(config, {config.dynamics.firstFrame, config.dynamics.lastFrame}),
                               [&](int, const Strands& guides) {
                                 const std::vector<double> turns = largestTurns(guides);
                                 out.emplace_back(at(turns, 0.5), at(turns, 0.95));
                               }))
          << shot << " at " << substeps << " substeps";
      return out;
    };
    const int own = config.dynamics.substeps;
    const std::vector<std::pair<double, double>> shots = run(own), many = run(64);
    ASSERT_EQ(shots.size(), size_t(config.dynamics.lastFrame - config.dynamics.firstFrame + 1)) << shot;
    ASSERT_EQ(many.size(), shots.size()) << shot;
    double median = 0.0, high = 0.0;
    for (size_t f = 0; f < shots.size(); ++f) {
      median = std::max(median, std::abs(shots[f].first - many[f].first));
      high = std::max(high, std::abs(shots[f].second - many[f].second));
    }
    EXPECT_LT(median, 12.0) << shot << ": the median guide's largest turn " << median << "° off";
    EXPECT_LT(high, 45.0) << shot << ": the 95th percentile's " << high << "° off";
    const std::string name = std::string(shot).substr(0, std::string(shot).find('/', 6));
    RecordProperty(name + "_median_off", std::to_string(median));
    RecordProperty(name + "_p95_off", std::to_string(high));
  }
}

// The memo's Fig. 5 settings (configs/pixar/target's Dynamics: strength, damping, smoothing, grids,
// substeps) on one lock against a displaced copy of itself: 100 hairs 16 cm long, roots 3 mm apart, and
// the same lock swung 30° about its roots (tips 8 cm away). The density force must carry the lock toward
// the copy as a lock: its points end a third as far from their counterparts as they began, its centroid
// goes at least two thirds of the way, and it does not puff out across the motion. With the shot's first
// settings (4, 2 and 1 cm grids handed over when E halved, strength 30, damping 4, no smoothing) the lock
// got there (distance 0.23 of its start, 0.81 of the way) but grew 5.4× across: hair that a swing throws
// outside the copy's density feels only its own density's slope, and nothing brings it back.
TEST(Springs, TheTargetShotsSettingsCarryALockToADisplacedCopy) {
  const Config config = loadConfig(
      std::filesystem::path(HAIRGEN_SOURCE_DIR) / "configs/pixar/target/setup.txt", {}, SetupUse::kRender);
  Dynamics d = config.dynamics;
  Strands rest, target;
  const double swing = glm::radians(30.0);
  for (int i = 0; i < 10; ++i)
    for (int j = 0; j < 10; ++j) {
      const glm::dvec3 root(0.003 * i, 0.0, 0.003 * j);
      rest.addStrand(straight(root, {0, -1, 0}, 0.16, 64));
      target.addStrand(straight(root, {std::sin(swing), -std::cos(swing), 0}, 0.16, 64));
    }
  Hairstyle style = config.hairstyle;
  style.gravity = 0.0;
  d.gravityAuto = false;
  d.gravity = 0.0;
  SpringHair hair(rest, style, d, Collision{}, &target);
  auto measure = [&](double& distance, glm::dvec3& centroid, double& width) {
    distance = 0.0;
    centroid = glm::dvec3(0.0);
    double lo = 1e9, hi = -1e9;
    for (size_t p = 0; p < rest.pointCount(); ++p) {
      distance += glm::length(hair.positions()[p] - glm::dvec3(target.points[p]));
      centroid += hair.positions()[p];
      lo = std::min(lo, hair.positions()[p].z);
      hi = std::max(hi, hair.positions()[p].z);
    }
    distance /= double(rest.pointCount());
    centroid /= double(rest.pointCount());
    width = hi - lo;
  };
  glm::dvec3 goal(0.0);
  for (const glm::vec3& q : target.points) goal += glm::dvec3(q);
  goal /= double(target.pointCount());
  double start = 0.0, startWidth = 0.0, distance = 0.0, width = 0.0, stretch = 0.0;
  glm::dvec3 from, centroid;
  measure(start, from, startWidth);
  for (int frame = d.firstFrame + 1; frame <= d.lastFrame; ++frame) {
    for (int s = 0; s < d.substeps; ++s)
      hair.step(AccelerationField{}, 1.0 / (d.frameRate * d.substeps), s == 0, s == d.substeps - 1);
    stretch = std::max(stretch, hair.maxStretch());
  }
  measure(distance, centroid, width);
  const double travelled = glm::dot(centroid - from, goal - from) / glm::dot(goal - from, goal - from);
  EXPECT_LT(distance, start / 3.0) << "from " << start << " m to " << distance << " m";
  EXPECT_GT(travelled, 2.0 / 3.0);
  EXPECT_LT(width, 2.0 * startWidth) << "across the motion " << startWidth << " m became " << width << " m";
  EXPECT_LT(stretch, 0.01);
  RecordProperty("distance_ratio", std::to_string(distance / start));
  RecordProperty("travelled", std::to_string(travelled));
  RecordProperty("width_ratio", std::to_string(width / startWidth));
}

// Density targeting and velocity smoothing give the same bits on 1, 2 and 4 threads: the lock of the
// test above, a second of the shot's settings.
TEST(Springs, DensityTargetingIsTheSameBitsOnAnyThreadCount) {
  const Config config = loadConfig(
      std::filesystem::path(HAIRGEN_SOURCE_DIR) / "configs/pixar/target/setup.txt", {}, SetupUse::kRender);
  const Dynamics& d = config.dynamics;
  Strands rest, target;
  for (int i = 0; i < 10; ++i)
    for (int j = 0; j < 10; ++j) {
      const glm::dvec3 root(0.003 * i, 0.0, 0.003 * j);
      rest.addStrand(straight(root, {0, -1, 0}, 0.16, 64));
      target.addStrand(straight(root, {0.5, -std::sqrt(0.75), 0}, 0.16, 64));
    }
  auto run = [&](size_t threads) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
    SpringHair hair(rest, config.hairstyle, d, Collision{}, &target);
    for (int frame = 0; frame < 24; ++frame)
      for (int s = 0; s < d.substeps; ++s)
        hair.step(AccelerationField{}, 1.0 / (d.frameRate * d.substeps), s == 0, s == d.substeps - 1);
    return hair.state();
  };
  const std::vector<double> one = run(1);
  EXPECT_TRUE(one == run(2));
  EXPECT_TRUE(one == run(4));
}

// The memo's Fig. 5 experiment as configs/pixar/target has it: the default coupe pushed toward a
// wind-blown frame of itself by density forces. Every frame lowers the energy of the grid it used (to
// a wobble of 5e-4 of that grid's start once settled, as points cross grid lines; a hand-over to a
// finer grid may raise a coarser one's, and the rule then goes back to it); E on the finest grid ends
// below a fifth of its start, the guides end within a quarter of their starting distance from their
// own points in the target, and no segment stretches by 1%. (With the shot's first settings, 1 cm
// grids from frame 4, E on the finest grid fell to 0.094 but the distance only to 0.75: a puff.)
TEST(Springs, ThePixarTargetShotApproachesItsTarget) {
  const Config config = loadConfig(
      std::filesystem::path(HAIRGEN_SOURCE_DIR) / "configs/pixar/target/setup.txt", {}, SetupUse::kRender);
  const Dynamics& d = config.dynamics;
  const Mesh wick = test::loadJob("default/setup.txt").wick;
  const Strands rest = grow(wick, config.hairstyle, config.collision, GrowOptions{}).guides;
  const Strands target = readStrands(d.densityTarget.path);
  SpringHair hair(rest, config.hairstyle, d, config.collision, &target);
  const size_t finest = hair.densityLevels() - 1;
  const double start = hair.densityEnergy(finest);
  // The guides and the target frame are the same strands (frame 36 of the wind shot from this rest):
  // the mean distance of each guide point to its own point in the target says where the hair went,
  // which the density energy alone does not (spreading the hair thin lowers it too).
  auto fromTarget = [&] {
    double sum = 0.0;
    for (size_t p = 0; p < rest.pointCount(); ++p)
      sum += glm::length(hair.positions()[p] - glm::dvec3(target.points[p]));
    return sum / double(rest.pointCount());
  };
  ASSERT_EQ(rest.firstPoint, target.firstPoint);
  const double startDistance = fromTarget();
  std::vector<double> levelStart, before(hair.densityLevels());
  for (size_t level = 0; level < hair.densityLevels(); ++level)
    levelStart.push_back(hair.densityEnergy(level));
  double previous = start, stretch = 0.0;
  int rises = 0;
  for (int frame = d.firstFrame + 1; frame <= d.lastFrame; ++frame) {
    for (size_t level = 0; level < hair.densityLevels(); ++level) before[level] = hair.densityEnergy(level);
    for (int s = 0; s < d.substeps; ++s)
      hair.step(AccelerationField{}, 1.0 / (d.frameRate * d.substeps), s == 0, s == d.substeps - 1);
    const size_t used = hair.densityLevel();
    if (hair.densityEnergy(used) > before[used] + 5e-4 * levelStart[used]) ++rises;
    previous = hair.densityEnergy(finest);
    stretch = std::max(stretch, hair.maxStretch());
  }
  EXPECT_EQ(rises, 0);
  EXPECT_LT(previous, 0.2 * start) << "E from " << start << " to " << previous;
  EXPECT_LT(stretch, 0.01);
  const double distance = fromTarget();
  EXPECT_LT(distance, 0.25 * startDistance) << "from " << startDistance << " m to " << distance << " m";
  RecordProperty("distance_ratio", std::to_string(distance / startDistance));
  RecordProperty("energy_ratio", std::to_string(previous / start));
  RecordProperty("max_stretch", std::to_string(stretch));
}

// The memo (§5.2) directs hair "with as little energy as possible": the Fig. 5 shot reaches its target
// (the guides' mean distance from their own points in it within 1.5 cm) with a peak kinetic energy no
// larger than that of the motion that made the target, the wind shot's first 36 frames (before: 4.2×,
// 7.5e-4 J against 1.8e-4 J). Kinetic energy at every substep, the hair's own (head frame).
TEST(Springs, DensityTargetingTakesNoMoreEnergyThanTheMotionThatMadeItsTarget) {
  const std::filesystem::path pixar = std::filesystem::path(HAIRGEN_SOURCE_DIR) / "configs/pixar";
  const Mesh wick = test::loadJob("default/setup.txt").wick;
  auto peak = [&](const char* shot, double* distance) {
    const Config config = loadConfig(pixar / shot / "setup.txt", {}, SetupUse::kRender);
    const Dynamics& d = config.dynamics;
    const Strands rest = grow(wick, config.hairstyle, config.collision, GrowOptions{}).guides;
    std::optional<Strands> target;
    if (d.densityTarget.given()) target = readStrands(d.densityTarget.path);
    SpringHair hair(rest, config.hairstyle, d, config.collision, target ? &*target : nullptr);
    const double gravity = dynamicsGravity(config.hairstyle, d);
    double most = 0.0;
    for (int frame = d.firstFrame + 1; frame <= d.lastFrame; ++frame)
      for (int s = 0; s < d.substeps; ++s) {
        const double t = double(frame - 1) + double(s) / double(d.substeps);
        hair.step(headFrameField(HeadState{}, windAt(d.wind, t), gravity), 1.0 / (d.frameRate * d.substeps),
                  s == 0, s == d.substeps - 1);
        most = std::max(most, hair.kineticEnergy());
      }
    if (distance) {
      double sum = 0.0;
      for (size_t p = 0; p < rest.pointCount(); ++p)
        sum += glm::length(hair.positions()[p] - glm::dvec3(target->points[p]));
      *distance = sum / double(rest.pointCount());
    }
    return most;
  };
  double distance = 0.0;
  const double source = peak("wind", nullptr), directed = peak("target", &distance);
  EXPECT_LE(directed, source) << "peak kinetic energy " << directed << " J, the wind shot's " << source
                              << " J";
  EXPECT_LT(distance, 0.015) << "mean distance from the target " << distance << " m";
  RecordProperty("peak_energy_ratio", std::to_string(directed / source));
  RecordProperty("distance_m", std::to_string(distance));
}

}  // namespace
}  // namespace hairgen
