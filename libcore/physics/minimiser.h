// What the guide minimisers (rosenbrock.h, quasi_newton.h) return, and why they stop.
#pragma once

#include <vector>

namespace hairgen {

// kEpsilon: the energy's change fell below its bar (Rosenbrock: over a stage, Epsilon × the energy
// scale; quasi-Newton: the decrease its model still predicts and the last one, both below the
// tolerance it is given); kStalled: no trial lowered it any more;
// kMaxStages: MaxIter's bound; kMaxEvaluations: the hard bound on evaluations.
enum class MinimiserStop { kEpsilon, kMaxStages, kStalled, kMaxEvaluations };
const char* name(MinimiserStop stop);

struct MinimiserResult {
  std::vector<double> x;
  double value = 0.0;
  int stages = 0;       // Rosenbrock's stages, or quasi-Newton iterations
  int evaluations = 0;  // calls of f (quasi-Newton: of f with its gradient)
  MinimiserStop stop = MinimiserStop::kMaxStages;
};

}  // namespace hairgen
