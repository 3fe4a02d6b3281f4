// A quasi-Newton minimiser (BFGS, Nocedal & Wright 2006 §6.1) on a function and its gradient, for
// `Minimiser bfgs`: the same Super-Helix energy as Rosenbrock's search, with its analytic gradient.
#pragma once

#include <functional>
#include <span>

#include "libcore/physics/minimiser.h"

namespace hairgen {

struct QuasiNewtonOptions {
  int maxIterations = 400;
  // Stop when both the decrease the quadratic model still predicts, ½ gᵀ H g, and the last
  // iteration's are below this (f's units).
  double tolerance = 1e-12;
  int maxEvaluations = 100000;  // hard bound, so a pathological f cannot loop forever
};

// f(x, gradient) returns f at x and writes its gradient (sized like x); a non-finite value is a
// point the line search steps back from. `inverseScale` is the first inverse-Hessian estimate's
// diagonal (positive; the inverse of f's curvature along each coordinate where that is known), and
// no step moves coordinate i by more than maxStep[i] (the line search starts shorter instead).
// Deterministic: no randomness, fixed evaluation order.
using ValueAndGradient = std::function<double(std::span<const double> x, std::span<double> gradient)>;
MinimiserResult minimizeQuasiNewton(const ValueAndGradient& f, std::span<const double> x0,
                                    std::span<const double> inverseScale, std::span<const double> maxStep,
                                    const QuasiNewtonOptions& options);

}  // namespace hairgen
