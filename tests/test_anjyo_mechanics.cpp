// Anjyo's dynamics (libcore/physics/anjyo_dynamics) against analytic mechanics: a rigid pendulum swings
// in its plane at any azimuth with the elliptic integral's period and keeps its energy; gravity sets the
// swing; a hanging hair in a steady wind, and after a nod, settles where the elastica of its own weight
// and bending stiffness does (the elastica solved here by shooting), whatever its segment count.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "libcore/physics/anjyo_dynamics.h"
#include "libcore/physics/head_motion.h"
#include "tests/test_util.h"

namespace hairgen {
namespace {

// The paper's equations alone: no damping, no rest spring, no pseudo-force.
Dynamics bare() {
  Dynamics d;
  d.given = true;
  d.damping = 0.0;
  d.restFrequencyAuto = false;
  d.restFrequency = 0.0;
  d.pseudoEpsilon = 1.0;
  return d;
}

// K(k), the complete elliptic integral of the first kind, by the arithmetic-geometric mean.
double ellipticK(double k) {
  double a = 1.0, b = std::sqrt(1.0 - k * k);
  for (int i = 0; i < 40; ++i) {
    const double next = 0.5 * (a + b);
    b = std::sqrt(a * b);
    a = next;
  }
  return M_PI / (2.0 * a);
}

struct Swing {
  double period = 0.0;      // s, from the zero crossings of the angle in the plane
  double outOfPlane = 0.0;  // radians, the most the segment left its plane
  double energy = 0.0;      // the most the energy drifted from its start, relative
};

// A one-segment hair L long hanging down (−y) under gravity g (the styled state's too: it hangs at rest),
// let go at `amplitude` in the vertical plane at `azimuth` from x, for `periods` of the small swing.
Swing swing(double azimuth, double amplitude, double g, double periods, double dt = 2e-4) {
  const double length = 0.1;
  Hairstyle style;
  style.gravity = g;
  AnjyoHair hair(test::chain(glm::dvec3(0.0), {{0, -1, 0}}, length), style, bare(), Collision{}, 0);
  // The rest frame of a hanging segment: pole +z, side +x; (a, b) is the rotation vector along them.
  const glm::dvec2 plane(std::sin(azimuth), std::cos(azimuth));
  hair.setSegmentState(0, 0, {amplitude * plane.x, amplitude * plane.y, 0.0, 0.0});
  AccelerationField field;
  field.base = {0.0, -g, 0.0};
  const glm::dvec3 normal(-std::sin(azimuth), 0.0, std::cos(azimuth));
  // Per unit inertia (I = m L²/3): ½ θ'² + (3g/2L)(1 − cos θ), θ' from the last step's turn about its
  // middle.
  auto energy = [&](const std::array<double, AnjyoHair::kStateValues>& s) {
    const double angle = glm::dot(glm::dvec2(s[0], s[1]), plane),
                 turn = glm::dot(glm::dvec2(s[2], s[3]), plane);
    const double rate = turn / dt, mid = angle - 0.5 * turn;
    return 0.5 * rate * rate + 1.5 * g / length * (1.0 - std::cos(mid));
  };
  Swing out;
  std::vector<double> crossings;
  double previous = amplitude, start = 0.0;
  const int steps = int(periods * 2.0 * M_PI * std::sqrt(2.0 * length / (3.0 * g)) / dt);
  for (int n = 1; n <= steps; ++n) {
    hair.step(field, dt, 1, false);
    const std::array<double, AnjyoHair::kStateValues> s = hair.segmentState(0, 0);
    const std::vector<glm::dvec3> nodes = hair.nodes();
    const glm::dvec3 dir = glm::normalize(nodes[1] - nodes[0]);
    out.outOfPlane = std::max(out.outOfPlane, std::asin(std::min(1.0, std::abs(glm::dot(dir, normal)))));
    if (n == 2) start = energy(s);
    if (n > 2) out.energy = std::max(out.energy, std::abs(energy(s) / start - 1.0));
    const double angle = glm::dot(glm::dvec2(s[0], s[1]), plane);
    if (previous > 0.0 && angle <= 0.0) crossings.push_back((n - 1 + previous / (previous - angle)) * dt);
    previous = angle;
  }
  if (crossings.size() > 1)
    out.period = (crossings.back() - crossings.front()) / double(crossings.size() - 1);
  return out;
}

// A rigid pendulum let go in a vertical plane stays in it (nothing pushes it out: gravity and the
// segment lie in the plane), whatever the plane's azimuth; it swings with the compound pendulum's period
// at its amplitude, T = 4 sqrt(2L/3g) K(sin(A/2)), and keeps its energy.
TEST(AnjyoMechanics, APendulumSwingsInItsPlaneAtAnyAzimuthWithTheEllipticPeriod) {
  const double g = 9.81, length = 0.1;
  for (double azimuth : {0.0, 30.0, 45.0, 60.0, 90.0})
    for (double amplitude : {5.0, 30.0, 90.0, 150.0}) {
      const double a = glm::radians(amplitude);
      const Swing s = swing(glm::radians(azimuth), a, g, 20.0);
      const double expected = 4.0 * std::sqrt(2.0 * length / (3.0 * g)) * ellipticK(std::sin(0.5 * a));
      const std::string at =
          "azimuth " + std::to_string(azimuth) + "°, amplitude " + std::to_string(amplitude) + "°";
      EXPECT_LT(glm::degrees(s.outOfPlane), 0.5) << at;
      EXPECT_NEAR(s.period / expected, 1.0, 3e-4)
          << at << ": period " << s.period << " s, exact " << expected;
      EXPECT_LT(s.energy, 0.01) << at;
    }
}

// Gravity sets the swing of a hair styled under it: the small-amplitude period scales as 1/sqrt(g).
// (A hair hanging at rest under the gravity it swings in: were the styling load subtracted as a constant
// force, nothing would pull it back and it would not swing at all.)
TEST(AnjyoMechanics, GravitySetsTheSwing) {
  const Swing earth = swing(0.3, glm::radians(5.0), 9.81, 10.0);
  const Swing heavy = swing(0.3, glm::radians(5.0), 30.0, 10.0);
  ASSERT_GT(earth.period, 0.0);
  ASSERT_GT(heavy.period, 0.0);
  EXPECT_NEAR(earth.period / heavy.period, std::sqrt(30.0 / 9.81), 1e-3);
}

// The planar elastica of a hanging hair L long, clamped at `root` radians from the vertical, under its
// weight and a wind w across (m/s²): EI θ'' = ρA (L − s)(g sin θ − w cos θ), θ(0) = root, θ'(L) = 0
// (θ from the downward vertical toward the wind, s from the root), shot from the root on θ'(0) with RK4
// and bisection. Returns the tip's place relative to the root (x across, y up).
glm::dvec2 elastica(const Hairstyle& style, double length, double root, double wind) {
  const double a = style.hairRadius1, b = style.hairRadius2, g = style.gravity;
  const double bending = style.young * M_PI * a * b * b * b / 4.0, linear = style.massDensity * M_PI * a * b;
  const int steps = 4000;
  const double h = length / steps;
  // Integrates from curvature k0 at the root: the curvature at the tip (or ±1 where θ runs away), and
  // the tip's place.
  auto shoot = [&](double k0, glm::dvec2& tip) {
    auto rate = [&](double s, double theta) {
      return linear * (length - s) * (g * std::sin(theta) - wind * std::cos(theta)) / bending;
    };
    double theta = root, k = k0;
    tip = glm::dvec2(0.0);
    for (int i = 0; i < steps; ++i) {
      const double s = i * h;
      const double t1 = k, k1 = rate(s, theta);
      const double t2 = k + 0.5 * h * k1, k2 = rate(s + 0.5 * h, theta + 0.5 * h * t1);
      const double t3 = k + 0.5 * h * k2, k3 = rate(s + 0.5 * h, theta + 0.5 * h * t2);
      const double t4 = k + h * k3, k4 = rate(s + h, theta + h * t3);
      const double next = theta + h / 6.0 * (t1 + 2.0 * t2 + 2.0 * t3 + t4);
      k += h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
      const double mid = 0.5 * (theta + next);
      tip += h * glm::dvec2(std::sin(mid), -std::cos(mid));
      theta = next;
      if (std::abs(theta - root) > 4.0) return theta > root ? 1.0 : -1.0;
    }
    return k;
  };
  double lo = -1e3, hi = 1e3;
  glm::dvec2 tip;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (shoot(mid, tip) > 0.0 ? hi : lo) = mid;
  }
  shoot(0.5 * (lo + hi), tip);
  return tip;
}

// A hair `segments` long hanging from the origin, at rest `root` radians from the vertical (toward +x),
// settled in the field `field` (head frame) by damping: its tip relative to its root.
glm::dvec3 settled(const Hairstyle& style, double length, int segments, double root,
                   const glm::dvec3& field) {
  Dynamics dynamics = bare();
  dynamics.restFrequencyAuto = true;  // the hair's own stiffness
  dynamics.damping = 4.0;
  AnjyoHair hair(
      test::chain(glm::dvec3(0.0),
                  std::vector<glm::dvec3>(size_t(segments), {std::sin(root), -std::cos(root), 0.0}),
                  length / segments),
      style, dynamics, Collision{}, 0);
  AccelerationField f;
  f.base = field;
  for (int n = 0; n < 96 * 12; ++n) hair.step(f, 1.0 / 96.0, 1, false);
  const std::vector<glm::dvec3> nodes = hair.nodes();
  return nodes.back() - nodes.front();
}

// A 20 cm hair hanging in a steady wind across it settles where the elastica does: within 10% of its
// deflection, at 5, 20 and 40 segments.
TEST(AnjyoMechanics, AHairInASteadyWindSettlesAtTheElasticasDeflection) {
  const Hairstyle style;
  const double length = 0.2;
  // The elastica's own figures (the issue's: 0.18, 0.55, 1.8 and 5.3 cm).
  const double reference[4] = {0.187, 0.561, 1.862, 5.386};
  int i = 0;
  for (double wind : {0.1, 0.3, 1.0, 3.0}) {
    const double expected = elastica(style, length, 0.0, wind).x;
    EXPECT_NEAR(expected * 100.0, reference[i++], 0.002) << "the elastica at " << wind << " m/s²";
    for (int segments : {5, 20, 40}) {
      const glm::dvec3 tip = settled(style, length, segments, 0.0, {wind, -style.gravity, 0.0});
      EXPECT_NEAR(tip.x / expected, 1.0, 0.1)
          << segments << " segments in " << wind << " m/s² of wind: " << tip.x * 100 << " cm, the elastica "
          << expected * 100 << " cm";
    }
  }
}

// After a 30° nod, held, a hanging hair hangs again: within 2° of the elastica clamped 30° from the
// vertical at its root (the angle of the root-to-tip chord from the vertical).
TEST(AnjyoMechanics, AfterANodAHairHangsAsTheElasticaDoes) {
  const Hairstyle style;
  const double length = 0.2, nod = glm::radians(30.0);
  const glm::dvec2 tip = elastica(style, length, nod, 0.0);
  const double expected = std::atan2(tip.x, -tip.y);
  // In the head's frame, nodded by 30° about z, gravity is turned by −30°; the hair hung straight down.
  HeadState head;
  head.pose.rotation = eulerRotation({0.0, 0.0, 30.0});
  const AccelerationField field = headFrameField(head, glm::dvec3(0.0), style.gravity);
  for (int segments : {5, 20, 40}) {
    const glm::dvec3 chord = head.pose.rotation * settled(style, length, segments, 0.0, field.base);
    const double angle = std::atan2(std::abs(chord.x), -chord.y);
    EXPECT_NEAR(glm::degrees(angle), glm::degrees(expected), 2.0) << segments << " segments";
  }
  EXPECT_LT(glm::degrees(expected), 4.0);
  EXPECT_GT(glm::degrees(expected), 1.0);
}

// How far a moving tip is from the finest cut's, relative to how far that tip travels.
struct TipError {
  double rms = 0.0, max = 0.0;
};

// A 20 cm hair of `segments` hanging straight down from the origin, with its own stiffness (the auto rest
// spring) and damping 1/s, after a 30° nod held (the field turned by 30° in the head's frame at t = 0):
// its tip relative to its root, every 1/96 s for 1.5 s (two swings), stepped at 1/960 s so that the
// time step's error is small against the segments'.
std::vector<glm::dvec3> nodTip(int segments) {
  const Hairstyle style;
  const double length = 0.2;
  Dynamics dynamics = bare();
  dynamics.restFrequencyAuto = true;
  dynamics.damping = 1.0;
  AnjyoHair hair(test::chain(glm::dvec3(0.0), std::vector<glm::dvec3>(size_t(segments), {0.0, -1.0, 0.0}),
                             length / segments),
                 style, dynamics, Collision{}, 0);
  HeadState head;
  head.pose.rotation = eulerRotation({0.0, 0.0, 30.0});
  const AccelerationField field = headFrameField(head, glm::dvec3(0.0), style.gravity);
  std::vector<glm::dvec3> tips;
  for (int frame = 0; frame < 144; ++frame) {
    for (int n = 0; n < 10; ++n) hair.step(field, 1.0 / 960.0, 1, false);
    const std::vector<glm::dvec3> nodes = hair.nodes();
    tips.push_back(nodes.back() - nodes.front());
  }
  return tips;
}

// Anjyo's hair is a chain of rigid segments standing for a continuous hair, so a moving tip converges on
// the continuous hair's as the segments get shorter, at first order (the error halves with each
// doubling: against 160 segments 5.4, 2.9, 1.4 and 0.6% RMS of the tip's travel at 5, 10, 20 and 40).
// Against 40 segments here: the tip's distance from the 40-segment tip, relative to that tip's travel,
// falls with every doubling of the count, and stays within the first order's figures (4.8/2.3/0.8% RMS,
// 9.9/4.4/1.5% at most, at 5/10/20 segments).
TEST(AnjyoMechanics, AMovingTipConvergesWithTheSegmentCount) {
  const std::vector<glm::dvec3> fine = nodTip(40);
  double travel = 0.0;
  for (const glm::dvec3& tip : fine) travel = std::max(travel, glm::length(tip - fine.front()));
  ASSERT_GT(travel, 0.01);
  std::vector<TipError> errors;
  for (int segments : {5, 10, 20}) {
    const std::vector<glm::dvec3> tips = nodTip(segments);
    TipError e;
    for (size_t i = 0; i < tips.size(); ++i) {
      const double d = glm::length(tips[i] - fine[i]) / travel;
      e.rms += d * d;
      e.max = std::max(e.max, d);
    }
    e.rms = std::sqrt(e.rms / double(tips.size()));
    errors.push_back(e);
  }
  const double rmsBound[3] = {0.06, 0.03, 0.012}, maxBound[3] = {0.12, 0.06, 0.025};
  for (size_t i = 0; i < errors.size(); ++i) {
    const int segments = 5 << i;
    EXPECT_LT(errors[i].rms, rmsBound[i]) << segments << " segments";
    EXPECT_LT(errors[i].max, maxBound[i]) << segments << " segments";
    if (i > 0) {
      EXPECT_LT(errors[i].rms, 0.6 * errors[i - 1].rms) << segments << " segments against half as many";
    }
  }
}

}  // namespace
}  // namespace hairgen
