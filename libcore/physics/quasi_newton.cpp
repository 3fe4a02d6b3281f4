// BFGS with a strong-Wolfe line search. The inverse Hessian estimate H is kept dense: a Super-Helix
// guide has 3 coordinates per element (24 for the default coupe, 768 at HairLengths' limit), and H·g
// and the rank-two update cost less than one evaluation of the energy's gradient, whose cost grows
// with the coordinates too.
#include "libcore/physics/quasi_newton.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace hairgen {
namespace {

// H = diag(scale); an entry that is not a positive finite number (a stiffness that underflowed) is 1,
// which the first step's curvature then rescales.
void resetInverse(std::vector<double>& h, std::span<const double> scale) {
  const size_t n = scale.size();
  std::fill(h.begin(), h.end(), 0.0);
  for (size_t i = 0; i < n; ++i) h[i * n + i] = std::isfinite(scale[i]) && scale[i] > 0.0 ? scale[i] : 1.0;
}

}  // namespace

MinimiserResult minimizeQuasiNewton(const ValueAndGradient& f, std::span<const double> x0,
                                    std::span<const double> inverseScale, std::span<const double> maxStep,
                                    const QuasiNewtonOptions& options) {
  constexpr double kArmijo = 1e-4;    // sufficient decrease: f(x + αp) ≤ f(x) + kArmijo α gᵀp
  constexpr double kCurvature = 0.9;  // |f'(x + αp)| ≤ kCurvature |f'(x)| along p
  constexpr int kMaxTrials = 40;
  const size_t n = x0.size();
  MinimiserResult result;
  result.x.assign(x0.begin(), x0.end());
  std::vector<double> g(n), trial(n), trialGradient(n), loPoint(n), loGradient(n), p(n), s(n), y(n), hy(n),
      h(n * n);
  auto evaluate = [&](std::span<const double> x, std::span<double> gradient) {
    ++result.evaluations;
    const double value = f(x, gradient);
    return std::isfinite(value) ? value : HUGE_VAL;
  };
  result.value = evaluate(result.x, g);
  resetInverse(h, inverseScale);
  bool fresh = true;  // H is still the given diagonal: scale it by the first step's curvature
  double lastDecrease = HUGE_VAL;
  result.stop = MinimiserStop::kMaxStages;
  for (int iteration = 0; iteration < options.maxIterations; ++iteration) {
    result.stages = iteration;
    // p = −H g; a direction that does not descend (H lost its positivity to rounding) restarts H.
    for (int attempt = 0; attempt < 2; ++attempt) {
      for (size_t i = 0; i < n; ++i) p[i] = -innerProduct(std::span(h).subspan(i * n, n), g);
      if (innerProduct(p, g) < 0.0) break;
      resetInverse(h, inverseScale);
      fresh = true;
    }
    const double slope = innerProduct(p, g);
    if (!(slope < 0.0) || (-0.5 * slope < options.tolerance && lastDecrease < options.tolerance)) {
      result.stop =
          slope < 0.0 || innerProduct(g, g) == 0.0 ? MinimiserStop::kEpsilon : MinimiserStop::kStalled;
      return result;
    }
    // A step satisfying the strong Wolfe conditions (sufficient decrease, and a slope along p that
    // has flattened to kCurvature of the first), bracketed and zoomed by safeguarded quadratic
    // interpolation (Nocedal & Wright Algorithms 3.5-3.6): it keeps yᵀs > 0, so the update is made,
    // except after a step that ends on the bound or a search that runs out of trials (then the
    // lowest point that passed the sufficient-decrease test is taken, and the update made only
    // where yᵀs > 0).
    double lo = 0.0, loValue = result.value, loSlope = slope, hi = HUGE_VAL, hiValue = HUGE_VAL;
    double longest = HUGE_VAL;  // the step at which some coordinate moves by its bound
    for (size_t i = 0; i < n; ++i)
      if (std::abs(p[i]) > 0.0) longest = std::min(longest, maxStep[i] / std::abs(p[i]));
    double alpha = std::min(1.0, longest);
    bool accepted = false, outOfEvaluations = false;
    for (int k = 0; k < kMaxTrials; ++k) {
      if (result.evaluations >= options.maxEvaluations) {
        outOfEvaluations = true;
        break;
      }
      for (size_t i = 0; i < n; ++i) trial[i] = result.x[i] + alpha * p[i];
      const double value = evaluate(trial, trialGradient);
      const double trialSlope = innerProduct(trialGradient, p);
      if (value > result.value + kArmijo * alpha * slope || value >= loValue) {
        hi = alpha;
        hiValue = value;
      } else {
        loGradient.swap(trialGradient);
        std::copy(trial.begin(), trial.end(), loPoint.begin());
        if (std::abs(trialSlope) <= -kCurvature * slope || (hi == HUGE_VAL && alpha == longest)) {
          lo = alpha;
          loValue = value;
          accepted = true;
          break;
        }
        if (trialSlope * (hi - lo) >= 0.0) {
          hi = lo;
          hiValue = loValue;
        }
        lo = alpha;
        loValue = value;
        loSlope = trialSlope;
      }
      if (hi == HUGE_VAL) {
        alpha = std::min(4.0 * alpha, longest);  // still descending: expand, within the bound
        continue;
      }
      const double width = hi - lo;
      double next = lo + 0.5 * width;
      if (hiValue < HUGE_VAL) {
        const double curvature = hiValue - loValue - loSlope * width;
        if (curvature > 0.0) next = lo - loSlope * width * width / (2.0 * curvature);
      }
      const double a = std::min(lo, hi), b = std::max(lo, hi), margin = 0.1 * (b - a);
      alpha = std::clamp(next, a + margin, b - margin);
    }
    if (!accepted && lo == 0.0) {
      result.stop = outOfEvaluations ? MinimiserStop::kMaxEvaluations : MinimiserStop::kStalled;
      return result;
    }
    for (size_t i = 0; i < n; ++i) {
      s[i] = loPoint[i] - result.x[i];
      y[i] = loGradient[i] - g[i];
    }
    result.x.swap(loPoint);
    g.swap(loGradient);
    lastDecrease = result.value - loValue;
    result.value = loValue;
    // H ← (I − ρ s yᵀ) H (I − ρ y sᵀ) + ρ s sᵀ, ρ = 1/(yᵀs), skipped where yᵀs ≤ 0 (no curvature
    // information the update could keep positive definite).
    const double sy = innerProduct(s, y);
    if (sy > 1e-14 * std::sqrt(innerProduct(s, s) * innerProduct(y, y))) {
      const double rho = 1.0 / sy;
      for (size_t i = 0; i < n; ++i) hy[i] = innerProduct(std::span(h).subspan(i * n, n), y);
      double yhy = innerProduct(y, hy);
      if (fresh) {
        const double gamma = sy / yhy;
        for (double& v : h) v *= gamma;
        for (double& v : hy) v *= gamma;
        yhy *= gamma;
        fresh = false;
      }
      // The upper triangle, mirrored: H stays exactly symmetric.
      for (size_t i = 0; i < n; ++i)
        for (size_t j = i; j < n; ++j) {
          h[i * n + j] += rho * ((1.0 + rho * yhy) * s[i] * s[j] - hy[i] * s[j] - s[i] * hy[j]);
          h[j * n + i] = h[i * n + j];
        }
    }
    if (outOfEvaluations) {
      result.stages = iteration + 1;  // this iteration's step was taken
      result.stop = MinimiserStop::kMaxEvaluations;
      return result;
    }
  }
  result.stages = options.maxIterations;
  return result;
}

}  // namespace hairgen
