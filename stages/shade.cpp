#include "stages/shade.h"

#include <algorithm>
#include <cmath>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_group.h>

#include "libcore/model/strand_frames.h"
#include "libcore/util/error.h"
#include "libcore/util/random.h"
#include "libcore/util/stopwatch.h"
#include "stages/preflight/estimate.h"

namespace hairgen {
namespace {

constexpr uint64_t kAmbientKey =
    0x616d6269656e74ull;  // "ambient": keeps these numbers apart from interpolate's

}  // namespace

double strandAmbient(uint64_t seed, uint32_t strandId, double mean, double deviation) {
  // Box-Muller on two uniforms; 1 − u keeps the logarithm finite.
  const double u1 = counterUniform(seed, strandId, kAmbientKey, 0),
               u2 = counterUniform(seed, strandId, kAmbientKey, 1);
  const double normal = std::sqrt(-2.0 * std::log(1.0 - u1)) * std::cos(2.0 * M_PI * u2);
  return std::max(0.0, mean + deviation * normal);
}

ShadeResult shade(Strands coupe, const Visuality& visuality, const RenderSettings& render,
                  const ShadeOptions& options) {
  if (coupe.points.empty()) throw InputError("the coupe has no points to build a volume from");
  const Bounds box = boundsInParallel(coupe.points);
  requireFits(estimateShade(render, coupe.strandCount(), coupe.pointCount(),
                            glm::dvec3(box.max) - glm::dvec3(box.min)),
              options.force);
  const uint64_t seed = options.seed;
  ShadeResult result;
  Stopwatch clock;
  // The normals are ~115 MB at 150,000 × 64, fresh pages the kernel faults in and clears for the one
  // thread that sizes the array (~50 ms). Sized in a task of their own beside the volume's parallel
  // loops, they take a core's share of those instead of a pause of every core.
  tbb::task_group sizing;
  sizing.run([&] { coupe.normals.resize(coupe.pointCount()); });
  try {
    result.volume = buildVolume(coupe, render.voxelSize, render.volumePadding, render.shellDensity,
                                options.distanceEverywhere);
  } catch (...) {
    sizing.wait();
    throw;
  }
  sizing.wait();
  result.timings.volume = clock.lap();
  Strands& out = result.coupe;
  out = std::move(coupe);
  volumeNormals(result.volume.distance, out, out.normals);
  if (wantsAmbient(visuality)) {
    // Every point belongs to one strand (firstPoint runs from 0 to the point count), so the strands,
    // each on its own, write every colour.
    out.colors.resize(out.pointCount());
    tbb::parallel_for(
        tbb::blocked_range<size_t>(0, out.strandCount(), 1024), [&](const tbb::blocked_range<size_t>& r) {
          for (size_t s = r.begin(); s < r.end(); ++s) {
            const uint32_t id = out.strandId.empty() ? static_cast<uint32_t>(s) : out.strandId[s];
            const float a = static_cast<float>(
                strandAmbient(seed, id, visuality.ambientMean, visuality.ambientDeviation));
            for (uint32_t p = out.firstPoint[s]; p < out.firstPoint[s + 1]; ++p) out.colors[p] = glm::vec3(a);
          }
        });
  }
  out.provenance = madeByHairgen("shade", seed, options.configDigest);
  result.timings.normals = clock.lap();
  return result;
}

Strands repose(const Strands& rest, const Strands& deformed) {
  if (!rest.strandId.empty() && !deformed.strandId.empty() && rest.strandId != deformed.strandId) {
    const size_t common = std::min(rest.strandId.size(), deformed.strandId.size());
    size_t i = 0;
    while (i < common && rest.strandId[i] == deformed.strandId[i]) ++i;
    throw InputError("the coupe's strand ids differ from the rest coupe's (" +
                     (i < common
                          ? "strand " + std::to_string(i) + " is id " + std::to_string(deformed.strandId[i]) +
                                " here and " + std::to_string(rest.strandId[i]) + " at rest"
                          : std::to_string(deformed.strandId.size()) + " strands here, " +
                                std::to_string(rest.strandId.size()) + " at rest") +
                     "); both must come from the same interpolate run");
  }
  Strands out = deformed;
  out.normals = reposeNormals(rest, deformed);
  if (out.colors.empty()) out.colors = rest.colors;
  out.provenance = rest.provenance;
  out.provenance.stage = "shade";
  out.provenance.frame = deformed.provenance.frame;  // the deformed coupe's frame, when it is one
  out.provenance.time = deformed.provenance.time;
  return out;
}

}  // namespace hairgen
