// Rosenbrock's method with Palmer's orthogonalisation, on problems with known minima.
#include <gtest/gtest.h>

#include <cmath>

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
  RosenbrockResult r = minimizeRosenbrock(banana, x0, steps, options);
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
  RosenbrockResult r = minimizeRosenbrock(f, x0, steps, options);
  EXPECT_LT(r.value, 1e-6 * f(x0));
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
  RosenbrockResult r = minimizeRosenbrock(bowl, x0, steps, RosenbrockOptions{});
  EXPECT_EQ(r.value, 0.0);
  EXPECT_EQ(r.stop, RosenbrockStop::kStalled);
  EXPECT_LT(r.evaluations, 200);
}

}  // namespace
}  // namespace hairgen
