// The restart state's checks, as restart_state.h describes them. Every bound is the one the simulation
// itself keeps after each step, so a state the simulation wrote always passes and a state it could not
// have written never does.
#include "libcore/io/restart_state.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include <glm/glm.hpp>

#include "libcore/util/error.h"
#include "libcore/util/fnv.h"
#include "libcore/util/text.h"

namespace hairgen {

std::optional<SpringSegmentFault> springSegmentFault(const glm::dvec3& start, const glm::dvec3& end,
                                                     const glm::dvec3& velocity, double restLength) {
  if (!std::isfinite(end.x) || !std::isfinite(end.y) || !std::isfinite(end.z) || !std::isfinite(velocity.x) ||
      !std::isfinite(velocity.y) || !std::isfinite(velocity.z))
    return SpringSegmentFault{};
  const double stretch = glm::length(end - start) / restLength - 1.0;
  if (!(std::abs(stretch) <= kMaxSpringStretch))
    return SpringSegmentFault{SpringSegmentFault::kStretch, stretch};
  return springSpeedFault(velocity);
}

std::optional<SpringSegmentFault> springSpeedFault(const glm::dvec3& velocity) {
  if (!std::isfinite(velocity.x) || !std::isfinite(velocity.y) || !std::isfinite(velocity.z))
    return SpringSegmentFault{};
  const double speed = glm::length(velocity);
  if (!(speed <= kMaxSpringSpeed)) return SpringSegmentFault{SpringSegmentFault::kSpeed, speed};
  return std::nullopt;
}

void requireSpringStateSize(size_t segments, size_t values, const std::string& source) {
  if (segments > 0 && values == segments * 6)
    throw InputError({source, 0},
                     "its simulation state is in the layout of an earlier hairgen (6 values a "
                     "segment, before the BDF2 step; this one keeps " +
                         std::to_string(kSpringStateValues) + "); simulate from the first frame");
  if (values != segments * kSpringStateValues)
    throw InputError({source, 0}, "its simulation state has " + std::to_string(values) +
                                      " values, and Model springs on these guides keeps " +
                                      std::to_string(segments * kSpringStateValues) + " (" +
                                      std::to_string(kSpringStateValues) + " per segment); restart from a " +
                                      "frame of the same guides and the same Model");
}

namespace {

void checkSpringState(const Strands& rest, const std::vector<double>& state, const std::string& source) {
  requireSpringStateSize(rest.pointCount() - rest.strandCount(), state.size(), source);
  // Segment by segment from each root (which the state does not hold: the head's, at rest), the
  // positions' distances against the rest lengths, and the velocities.
  for (size_t s = 0; s < rest.strandCount(); ++s) {
    const uint32_t p0 = rest.firstPoint[s], count = rest.pointsOf(s);
    glm::dvec3 previous(rest.points[p0]);
    for (uint32_t j = 1; j < count; ++j) {
      const double* v = &state[kSpringStateValues * (p0 - s + j - 1)];
      const glm::dvec3 x(v[0], v[1], v[2]), velocity(v[3], v[4], v[5]);
      auto refuse = [&](const std::string& what) {
        throw InputError({source, 0}, "its simulation state's strand " + std::to_string(s) + ", point " +
                                          std::to_string(j) + " " + what +
                                          "; no simulation writes that: simulate from the first frame");
      };
      const double restLength =
          glm::length(glm::dvec3(rest.points[p0 + j]) - glm::dvec3(rest.points[p0 + j - 1]));
      std::optional<SpringSegmentFault> fault = springSegmentFault(previous, x, velocity, restLength);
      // The history's velocities (a substep before, the last move) under the velocity's bounds; the
      // position's fault first.
      for (const double* earlier : {v + 6, v + 9})
        if (const std::optional<SpringSegmentFault> f =
                springSpeedFault(glm::dvec3(earlier[0], earlier[1], earlier[2]));
            f && (!fault || f->kind == SpringSegmentFault::kNotFinite))
          fault = f;
      if (fault && fault->kind == SpringSegmentFault::kNotFinite) refuse("holds a value that is not finite");
      if (!(restLength > 0.0)) refuse("follows a rest segment of no length");  // the guides', not the state's
      if (fault && fault->kind == SpringSegmentFault::kStretch)
        refuse("ends a segment " + formatReal(100.0 * fault->value) + "% off its rest length (the bound is " +
               formatReal(100.0 * kMaxSpringStretch) + "%)");
      if (fault)
        refuse("moves at " + formatReal(fault->value) + " m/s (the bound is " + formatReal(kMaxSpringSpeed) +
               " m/s)");
      previous = x;
    }
  }
}

void checkAnjyoState(const Strands& rest, const std::vector<double>& state, const std::string& source) {
  if (state.size() < kAnjyoStateHeader || state[0] != kAnjyoStateTag || state[1] != double(kAnjyoLanes) ||
      state[2] != double(kAnjyoStateValues))
    throw InputError({source, 0},
                     "its simulation state is not in the layout this hairgen keeps (an earlier "
                     "version, or another model's); simulate from the first frame");
  const size_t expected = anjyoStateSize(rest);
  if (state.size() != expected)
    throw InputError({source, 0}, "its simulation state is for other guides (" +
                                      std::to_string(state.size()) + " values, these need " +
                                      std::to_string(expected) +
                                      "); restart from a frame of the same guides");
  const size_t values = (state.size() - kAnjyoStateHeader) * 2;
  for (size_t i = 0; i < values; ++i) {
    float value;
    std::memcpy(&value, reinterpret_cast<const char*>(state.data() + kAnjyoStateHeader) + i * sizeof(float),
                sizeof(float));
    const bool angle = (i / kAnjyoLanes) % kAnjyoStateValues < 2;
    if (!(std::abs(value) <= (angle ? kMaxAnjyoAngle : kMaxAnjyoTurn)))
      throw InputError({source, 0}, std::string("its simulation state holds ") +
                                        (angle ? "an angle" : "a turn") + " that is not finite or beyond " +
                                        formatReal(angle ? kMaxAnjyoAngle : kMaxAnjyoTurn) +
                                        " rad; simulate from the first frame");
  }
}

}  // namespace

size_t anjyoStateSize(const Strands& rest) {
  // Per block of kAnjyoLanes strands, as many segments as its longest strand has.
  const size_t strands = rest.strandCount();
  size_t segments = 0;
  for (size_t b = 0; b < strands; b += kAnjyoLanes) {
    uint32_t most = 0;
    for (size_t s = b; s < std::min(strands, b + kAnjyoLanes); ++s)
      most = std::max(most, rest.pointsOf(s) > 0 ? rest.pointsOf(s) - 1 : 0u);
    segments += most;
  }
  return kAnjyoStateHeader + segments * kAnjyoStateValues * kAnjyoLanes / 2;
}

std::string restGuidesDigest(const Strands& rest) {
  // fnv1aLanes: the digest is computed at every simulate call, over megabytes of points.
  const uint64_t counts[2] = {rest.strandCount(), rest.pointCount()};
  uint64_t hash = fnv1aLanes(counts, sizeof counts, kFnvOffsetBasis);
  hash = fnv1aLanes(rest.firstPoint.data(), rest.firstPoint.size() * sizeof(uint32_t), hash);
  hash = fnv1aLanes(rest.points.data(), rest.points.size() * sizeof(glm::vec3), hash);
  hash = fnv1aLanes(rest.tangents.data(), rest.tangents.size() * sizeof(glm::vec3), hash);
  return formatDigest(hash);
}

void checkStateValues(const Strands& rest, const std::vector<double>& state, DynamicsModel model,
                      const std::string& source) {
  if (model == DynamicsModel::kSprings)
    checkSpringState(rest, state, source);
  else
    checkAnjyoState(rest, state, source);
}

void checkRestartState(const Strands& rest, const Strands& cache, const RestartExpectation& expected,
                       const std::string& source) {
  const FileLoc where{source, 0};
  const Provenance& p = cache.provenance;
  if (p.stage != "simulate" || !p.frame || *p.frame != expected.frame || cache.simulationState.empty())
    throw InputError(where, "is not frame " + std::to_string(expected.frame) +
                                " of a simulation with its restart state; simulate from the first frame");
  if (p.configDigest != expected.configDigest)
    throw InputError(where, "was simulated with another configuration (digest " + p.configDigest +
                                ", this one " + expected.configDigest + "); simulate from the first frame");
  if (p.restDigest.empty())
    throw InputError(where, "was made by another hairgen (" + (p.producer.empty() ? "unknown" : p.producer) +
                                "), which does not record the rest guides it started from; simulate from "
                                "the first frame");
  if (p.restDigest != expected.restDigest)
    throw InputError(where, "was simulated from other rest guides (digest " + p.restDigest + ", --guides " +
                                expected.restDigest + "); restart from a frame of the same guides");
  if (cache.firstPoint != rest.firstPoint)
    throw InputError(where, "holds other strands than the guides; restart from a frame of the same guides");
  checkStateValues(rest, cache.simulationState, expected.model, source);
}

}  // namespace hairgen
