#include "stages/shade.h"

#include <cmath>

#include "libcore/random.h"

namespace hairgen {
namespace {

constexpr uint64_t kAmbientKey = 0x616d6269656e74ull;  // "ambient": keeps these numbers apart from interpolate's

}  // namespace

double strandAmbient(uint64_t seed, uint32_t strandId, double mean, double deviation) {
  // Box-Muller on two uniforms; 1 − u keeps the logarithm finite.
  const double u1 = counterUniform(seed, strandId, kAmbientKey, 0), u2 = counterUniform(seed, strandId, kAmbientKey, 1);
  const double normal = std::sqrt(-2.0 * std::log(1.0 - u1)) * std::cos(2.0 * M_PI * u2);
  return std::max(0.0, mean + deviation * normal);
}

Strands shade(const Strands& coupe, const Visuality& visuality, uint64_t seed, const std::string& configDigest) {
  Strands out = coupe;
  out.colors.assign(out.pointCount(), glm::vec3(1.0f));
  for (size_t s = 0; s < out.strandCount(); ++s) {
    const uint32_t id = out.strandId.empty() ? static_cast<uint32_t>(s) : out.strandId[s];
    const float a = static_cast<float>(strandAmbient(seed, id, visuality.ambientMean, visuality.ambientDeviation));
    for (uint32_t p = out.firstPoint[s]; p < out.firstPoint[s + 1]; ++p) out.colors[p] = glm::vec3(a);
  }
  out.provenance = {"hairgen " HAIRGEN_VERSION, "shade", seed, configDigest};
  return out;
}

}  // namespace hairgen
