// The shade stage: per-strand shading attributes written into the cache. Today: Anjyo's per-strand
// ambient coefficient (Anjyo et al. 1992 §4.1), drawn from N(AmbientMean, AmbientDeviation) by a
// counter-based generator keyed by (seed, strand id), clamped at 0, and stored as the grey per-vertex
// colour (a, a, a) that every shading model multiplies its ambient and diffuse colours by.
#pragma once

#include <cstdint>
#include <string>

#include "libcore/params.h"
#include "libcore/strands.h"

namespace hairgen {

double strandAmbient(uint64_t seed, uint32_t strandId, double mean, double deviation);

// Whether a Setup asks for the stage (an ambient distribution other than the constant 1).
inline bool wantsShade(const Visuality& v) { return v.ambientDeviation > 0.0 || v.ambientMean != 1.0; }

Strands shade(const Strands& coupe, const Visuality& visuality, uint64_t seed, const std::string& configDigest);

}  // namespace hairgen
