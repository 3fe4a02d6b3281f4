// What the guide minimisers (rosenbrock.h, quasi_newton.h) return, and why they stop.
#pragma once

#include <span>
#include <vector>

namespace hairgen {

// kEpsilon: the energy's change fell below its bar (Rosenbrock: over a stage, Epsilon × the energy
// scale; quasi-Newton: the decrease its model still predicts and the last one, both below the
// tolerance it is given); kStalled: no trial lowered it any more;
// kMaxStages: MaxIter's bound; kMaxEvaluations: the hard bound on evaluations.
enum class MinimiserStop { kEpsilon, kMaxStages, kStalled, kMaxEvaluations };
inline const char* name(MinimiserStop stop) {
  switch (stop) {
    case MinimiserStop::kEpsilon:
      return "epsilon";
    case MinimiserStop::kStalled:
      return "stalled";
    case MinimiserStop::kMaxEvaluations:
      return "maxEvaluations";
    case MinimiserStop::kMaxStages:
      break;
  }
  return "maxIter";
}

struct MinimiserResult {
  std::vector<double> x;
  double value = 0.0;
  int stages = 0;       // Rosenbrock's stages, or quasi-Newton iterations
  int evaluations = 0;  // calls of f (quasi-Newton: of f with its gradient)
  MinimiserStop stop = MinimiserStop::kMaxStages;
};

// Σ a_i b_i, in index order.
inline double innerProduct(std::span<const double> a, std::span<const double> b) {
  double s = 0.0;
  for (size_t i = 0; i < a.size(); ++i) s += a[i] * b[i];
  return s;
}

}  // namespace hairgen
