// Rosenbrock's method with Palmer's orthogonalisation, and BFGS, on problems with known minima.
#include <gtest/gtest.h>

#include <cmath>

#include "libcore/physics/quasi_newton.h"
#include "libcore/physics/rosenbrock.h"

namespace hairgen {
namespace {

TEST(Rosenbrock, FindsTheBananaMinimum) {
  auto banana = [](std::span<const double> x) {
    return (1 - x[0]) * (1 - x[0]) + 100 * std::pow(x[1] - x[0] * x[0], 2);
  };
  std::vector<double> x0 = {-1.2, 1.0}, steps = {0.1, 0.1};
  RosenbrockOptions options;
  options.maxStages = 1000;
  options.epsilon = 1e-16;
  MinimiserResult r = minimizeRosenbrock(banana, x0, steps, options);
  EXPECT_NEAR(r.x[0], 1.0, 1e-4);
  EXPECT_NEAR(r.x[1], 1.0, 1e-4);
  EXPECT_LT(r.value, 1e-8);
}

TEST(Rosenbrock, SolvesAnIllConditionedQuadraticIn15Dimensions) {
  // f = Σ c_i (R x − t)_i² with condition number 1e4 and a rotation mixing every coordinate.
  const int n = 15;
  std::vector<double> target(n);
  for (int i = 0; i < n; ++i) target[i] = std::sin(1.0 + i);
  auto f = [&](std::span<const double> x) {
    double sum = 0.0;
    for (int i = 0; i < n; ++i) {
      double y = 0.0;
      for (int j = 0; j < n; ++j) y += std::cos(0.3 * (i + 1) * (j + 1)) * (x[j] - target[j]) / std::sqrt(n);
      sum += std::pow(10.0, 4.0 * i / (n - 1)) * y * y;
    }
    return sum;
  };
  std::vector<double> x0(n, 0.0), steps(n, 0.1);
  RosenbrockOptions options;
  options.maxStages = 5000;
  options.epsilon = 1e-18;
  options.energyScale = f(x0);
  MinimiserResult r = minimizeRosenbrock(f, x0, steps, options);
  EXPECT_LT(r.value, 1e-6 * f(x0));
}

TEST(QuasiNewton, FindsTheBananaMinimumInFewEvaluations) {
  auto banana = [](std::span<const double> x, std::span<double> g) {
    const double a = 1 - x[0], b = x[1] - x[0] * x[0];
    g[0] = -2 * a - 400 * x[0] * b;
    g[1] = 200 * b;
    return a * a + 100 * b * b;
  };
  std::vector<double> x0 = {-1.2, 1.0}, scale = {1.0, 1.0}, maxStep = {0.5, 0.5};
  QuasiNewtonOptions options;
  options.tolerance = 1e-20;
  MinimiserResult r = minimizeQuasiNewton(banana, x0, scale, maxStep, options);
  EXPECT_EQ(r.stop, MinimiserStop::kEpsilon);
  EXPECT_NEAR(r.x[0], 1.0, 1e-8);
  EXPECT_NEAR(r.x[1], 1.0, 1e-8);
  EXPECT_LT(r.evaluations, 100);  // Rosenbrock's search takes thousands here
}

TEST(QuasiNewton, SolvesAnIllConditionedQuadraticExactlyAndStepsBackFromNonFiniteValues) {
  // f = Σ c_i y_i², y = R(x − t), condition number 1e6; outside |x_0| < 5 f is NaN, where the
  // start's first full step lands.
  const int n = 12;
  std::vector<double> target(n);
  for (int i = 0; i < n; ++i) target[i] = std::sin(1.0 + i);
  // R = I − 2vvᵀ/|v|², a reflection: orthogonal, and it mixes every coordinate.
  std::vector<double> v(n);
  double vv = 0.0;
  for (int i = 0; i < n; ++i) vv += (v[i] = std::cos(2.0 + 0.7 * i)) * v[i];
  auto mix = [&](int i, int j) { return (i == j ? 1.0 : 0.0) - 2.0 * v[i] * v[j] / vv; };
  auto f = [&](std::span<const double> x, std::span<double> g) {
    if (std::abs(x[0]) >= 5.0) return std::nan("");
    std::fill(g.begin(), g.end(), 0.0);
    double sum = 0.0;
    for (int i = 0; i < n; ++i) {
      double y = 0.0;
      for (int j = 0; j < n; ++j) y += mix(i, j) * (x[j] - target[j]);
      const double c = std::pow(10.0, 6.0 * i / (n - 1));
      sum += c * y * y;
      for (int j = 0; j < n; ++j) g[j] += 2 * c * y * mix(i, j);
    }
    return sum;
  };
  std::vector<double> x0(n, 0.0), scale(n, 1.0), maxStep(n, 100.0), g(n);
  x0[0] = 4.9;
  QuasiNewtonOptions options;
  options.tolerance = 1e-12 * f(x0, g);
  MinimiserResult r = minimizeQuasiNewton(f, x0, scale, maxStep, options);
  EXPECT_EQ(r.stop, MinimiserStop::kEpsilon);
  EXPECT_LT(r.value, 1e-10 * f(x0, g)) << r.stages << " iterations, " << r.evaluations << " evaluations";
  for (int i = 0; i < n; ++i) EXPECT_NEAR(r.x[i], target[i], 1e-3);
  // The same bits again: no state outside the call.
  MinimiserResult again = minimizeQuasiNewton(f, x0, scale, maxStep, options);
  EXPECT_EQ(again.x, r.x);
  EXPECT_EQ(again.evaluations, r.evaluations);
}

TEST(QuasiNewton, NeverStepsAnyCoordinateFurtherThanItsBound) {
  // f = (x − 10)² from 0 with H = 0.01: the full step reaches 0.2 and the slope has hardly flattened,
  // so the search expands (0.2, 0.8, 3.2, …); the bound of 3 per step must stop it at 3.
  double farthest = 0.0;
  auto f = [&](std::span<const double> x, std::span<double> g) {
    farthest = std::max(farthest, std::abs(x[0]));
    g[0] = 2.0 * (x[0] - 10.0);
    return (x[0] - 10.0) * (x[0] - 10.0);
  };
  std::vector<double> x0 = {0.0}, scale = {0.01}, maxStep = {3.0};
  QuasiNewtonOptions options;
  options.maxIterations = 1;
  MinimiserResult r = minimizeQuasiNewton(f, x0, scale, maxStep, options);
  EXPECT_LE(farthest, 3.0);
  EXPECT_EQ(r.x[0], 3.0);
  // Unbounded, the same search goes past it.
  farthest = 0.0;
  maxStep[0] = 1e9;
  minimizeQuasiNewton(f, x0, scale, maxStep, options);
  EXPECT_GT(farthest, 3.0);
}

TEST(QuasiNewton, AnUnderflowedScaleOrAnEvaluationBoundStillEndsAtTheLowestPointFound) {
  // A zero or infinite first inverse-Hessian entry (a stiffness that underflowed) must not poison the
  // direction with 0·∞; and when the evaluations run out mid-search, the lowest point found is kept.
  auto f = [](std::span<const double> x, std::span<double> g) {
    g[0] = 2.0 * (x[0] - 1.0);
    g[1] = 20.0 * (x[1] + 2.0);
    return (x[0] - 1.0) * (x[0] - 1.0) + 10.0 * (x[1] + 2.0) * (x[1] + 2.0);
  };
  std::vector<double> x0 = {0.0, 0.0}, scale = {HUGE_VAL, 0.0}, maxStep = {10.0, 10.0}, g(2);
  QuasiNewtonOptions options;
  options.tolerance = 1e-20;
  MinimiserResult r = minimizeQuasiNewton(f, x0, scale, maxStep, options);
  EXPECT_EQ(r.stop, MinimiserStop::kEpsilon);
  EXPECT_NEAR(r.x[0], 1.0, 1e-8);
  EXPECT_NEAR(r.x[1], -2.0, 1e-8);
  for (int bound = 1; bound < 12; ++bound) {
    options.maxEvaluations = bound;
    MinimiserResult cut = minimizeQuasiNewton(f, x0, scale, maxStep, options);
    EXPECT_LE(cut.evaluations, bound);
    EXPECT_LE(cut.stages, cut.evaluations - 1);  // an iteration takes at least one evaluation after x0's
    if (cut.x != x0) {
      EXPECT_GE(cut.stages, 1) << bound;  // a step taken is an iteration counted
    }
    EXPECT_EQ(cut.value, f(cut.x, g)) << bound;  // the value of the point returned
    EXPECT_LE(cut.value, f(x0, g));
  }
  // Cut mid-search while it expands toward the minimum of (x − 10)² (from 0, H = 0.01: trials at
  // 0.2, 0.8, 3.2): the point reached is a step taken, and an iteration counted.
  auto far = [](std::span<const double> x, std::span<double> gradient) {
    gradient[0] = 2.0 * (x[0] - 10.0);
    return (x[0] - 10.0) * (x[0] - 10.0);
  };
  std::vector<double> origin = {0.0}, small = {0.01}, unbounded = {1e9};
  for (int bound = 2; bound <= 3; ++bound) {
    options.maxEvaluations = bound;
    MinimiserResult cut = minimizeQuasiNewton(far, origin, small, unbounded, options);
    EXPECT_EQ(cut.stop, MinimiserStop::kMaxEvaluations);
    EXPECT_GT(cut.x[0], 0.0) << bound;
    EXPECT_EQ(cut.stages, 1) << bound;
  }
}

TEST(Rosenbrock, PalmerDirectionsStayOrthonormalWhenAnAdvanceIsZero) {
  std::vector<std::vector<double>> xi = {{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}, {0, 0, 0, 1}};
  for (auto d : {std::vector<double>{0.5, 0.0, -0.2, 0.1}, std::vector<double>{0.0, 0.3, 0.0, 0.0},
                 std::vector<double>{1.0, 0.0, 0.0, 0.0}}) {
    auto out = palmerDirections(xi, d);
    for (size_t i = 0; i < 4; ++i)
      for (size_t j = 0; j < 4; ++j) {
        double dot = 0.0;
        for (size_t k = 0; k < 4; ++k) dot += out[i][k] * out[j][k];
        EXPECT_NEAR(dot, i == j ? 1.0 : 0.0, 1e-12) << i << "," << j;
        EXPECT_TRUE(std::isfinite(dot));
      }
    // The first new direction is the total advance.
    double norm = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2] + d[3] * d[3]);
    for (size_t k = 0; k < 4; ++k) EXPECT_NEAR(out[0][k], d[k] / norm, 1e-12);
  }
}

TEST(Rosenbrock, StopsAtAMinimumItStartsOn) {
  auto bowl = [](std::span<const double> x) { return x[0] * x[0] + x[1] * x[1]; };
  std::vector<double> x0 = {0.0, 0.0}, steps = {1.0, 1.0};
  MinimiserResult r = minimizeRosenbrock(bowl, x0, steps, RosenbrockOptions{});
  EXPECT_EQ(r.value, 0.0);
  EXPECT_EQ(r.stop, MinimiserStop::kStalled);
  EXPECT_LT(r.evaluations, 200);
}

}  // namespace
}  // namespace hairgen
