// The shade stage: shading attributes written into the cache.
// - Petrovic et al. 2005 §3-4: the strands' density grid, the signed distance to the hair's shell and
//   the shading normal N = ∇S at every vertex (the cache's normals), for `ShadingModel volumetric`.
// - Anjyo et al. 1992 §4.1: a per-strand ambient coefficient drawn from N(AmbientMean,
//   AmbientDeviation) by a counter-based generator keyed by (seed, strand id), clamped at 0, stored as
//   the grey per-vertex colour (a, a, a) that every shading model multiplies its ambient and diffuse
//   colours by; written only when the distribution is not the constant 1, so a cache's own colours
//   survive otherwise.
// And the paper's way of shading animated hair: the rest pose's normals re-posed onto a deformed coupe
// through parallel-transport frames, with no volume built.
#pragma once

#include <cstdint>
#include <string>

#include "libcore/config/params.h"
#include "libcore/model/strands.h"
#include "libcore/volume/shell.h"

namespace hairgen {

double strandAmbient(uint64_t seed, uint32_t strandId, double mean, double deviation);

// Whether a Setup asks for the stage: volumetric shading, or an ambient distribution other than 1.
inline bool wantsAmbient(const Visuality& v) {
  return v.ambientDeviation > 0.0 || v.ambientMean != 1.0;
}
inline bool wantsShade(const Visuality& v, const RenderSettings& r) {
  return wantsAmbient(v) || r.shadingModel == ShadingModel::kVolumetric;
}

struct ShadeTimings {
  double volume = 0.0;   // splat, smoothing, signed distance
  double normals = 0.0;  // ∇S at the vertices, and the ambient colours
};

struct ShadeResult {
  Strands coupe;
  HairVolume volume;  // its distance exact everywhere only with ShadeOptions::distanceEverywhere
  ShadeTimings timings;
};

struct ShadeOptions {
  uint64_t seed = 0;         // keys the per-strand ambient
  std::string configDigest;  // recorded in the coupe's provenance
  bool force = false;        // run work estimated to take absurdly long (never work that cannot fit)
  // The volume's signed distance exact at every node (for a volume written out, `--vdb`); otherwise
  // only where the normals read it (buildVolume), the same normals for less work.
  bool distanceEverywhere = false;
};

// Normals from the coupe's own volume (VoxelSize, VolumePadding and ShellDensity of Render Info), and
// the ambient colours when `visuality` asks for them. The grid is estimated before it is allocated.
// Takes the coupe by value: a caller done with it moves it in, and 10 million vertices are not copied.
ShadeResult shade(Strands coupe, const Visuality& visuality, const RenderSettings& render,
                  const ShadeOptions& options);

// `deformed` with the normals of `rest` (a shaded coupe of the same strands) re-posed onto it, and the
// rest's colours where `deformed` has none. InputError when the two coupes differ in strands, vertex
// counts or strand ids, or `rest` has no normals.
Strands repose(const Strands& rest, const Strands& deformed);

}  // namespace hairgen
