// Rosenbrock's direct search (Rosenbrock 1960) with Palmer's orthogonalisation (Palmer 1969), as
// described in Lansink 2010 §4.1.3: no derivatives, only function values.
#pragma once

#include <functional>
#include <span>
#include <vector>

#include "libcore/physics/minimiser.h"

namespace hairgen {

struct RosenbrockOptions {
  int maxStages = 20;        // stages at most (the thesis' MaxIter)
  double epsilon = 1e-4;     // a stage that lowers f by less than epsilon · energyScale ends the search
  double energyScale = 1.0;  // what "relative" is relative to (same units as f)
  double expand = 3.0;       // step factor after a success
  double contract = -0.5;    // step factor after a failure (reverses the direction)
  double minStepFraction =
      1e-9;  // a direction whose step shrank below this fraction of its initial step is spent
  double minRestartFraction = 1e-3;  // a new stage's steps: the last ones × expand, at least this × initial
  int maxEvaluations = 1000000;      // hard bound, so a pathological f cannot loop forever
};

// Minimises f from x0 with initial step sizes `steps` (one per coordinate, non-zero).
// f is called with a span it must not keep. Deterministic: no randomness, fixed evaluation order.
MinimiserResult minimizeRosenbrock(const std::function<double(std::span<const double>)>& f,
                                   std::span<const double> x0, std::span<const double> steps,
                                   const RosenbrockOptions& options);

// Palmer's orthonormal directions for the next stage from the old directions `xi` (rows) and the
// total advance `d` along each; well defined when some advances are zero.
std::vector<std::vector<double>> palmerDirections(const std::vector<std::vector<double>>& xi,
                                                  std::span<const double> d);

}  // namespace hairgen
