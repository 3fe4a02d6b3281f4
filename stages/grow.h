// The grow stage: one Super-Helix guide per wick vertex, at the static equilibrium of elasticity,
// gravity and penalty collisions (Lansink 2010 §4.1.1-4.1.4.2, DESIGN §5).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "libcore/config/params.h"
#include "libcore/model/mesh.h"
#include "libcore/model/strands.h"
#include "libcore/physics/quasi_newton.h"
#include "libcore/physics/rosenbrock.h"
#include "libcore/physics/strand_energy.h"
#include "libcore/util/progress.h"

namespace hairgen {

struct GrowOptions {
  std::string configDigest;      // recorded in the guides' provenance
  Progress* progress = nullptr;  // advanced once per guide
  bool force = false;            // run work estimated to take absurdly long (never work that cannot fit)
  // Grow only the guides of wick vertices [first, end) (`grow --shard K/N`), recorded in the provenance;
  // each guide is the one the whole run grows, so `hairgen merge` of the shards gives the whole file.
  std::optional<ShardRange> shard{};
};

// What minimisation did for one guide.
struct GuideReport {
  uint32_t follicle = 0;
  std::vector<double> coordinates;  // the 3N generalised coordinates found, 1/m
  EnergyTerms start, end;           // joules
  int stages = 0;
  int evaluations = 0;
  MinimiserStop stop = MinimiserStop::kMaxStages;
};

struct GrowResult {
  Strands guides;  // one strand per wick vertex (of the shard), in vertex order; points every VisualityStep,
                   // tangents
  std::vector<GuideReport> reports;
  long long evaluations = 0;
};

// Grows every guide (in parallel; the result does not depend on the thread count). Throws InputError
// for a wick vertex with a zero or non-finite normal and NumericError naming the guide whose energy is
// not finite.
GrowResult grow(const Mesh& wick, const Hairstyle& style, const Collision& collision,
                const GrowOptions& options);

// Each follicle's height fraction in [0, 1] between the lowest and the highest wick vertex: how far
// its layered envelope reaches (thesis §4.1.2.2). All 0 for a flat wick.
std::vector<double> follicleEnvelopes(const Mesh& wick);

// One guide, for tests and benchmarks.
GuideReport growGuide(const RodFrame& root, double envelope, const Hairstyle& style,
                      const Collision& collision);

// The whole grow stage for Model cantilever: one hair per wick vertex, its nodes as the guide's points.
// grow() checks the wick and dispatches here.
GrowResult growCantilever(const Mesh& wick, const Hairstyle& style, const Collision& collision,
                          const GrowOptions& options);

}  // namespace hairgen
