// Restart states (DESIGN §8): what `hairgen simulate` keeps in every frame's cache so that a shot split
// at any frame resumes with the same bytes as one run (the DYNS chunk, Strands::simulationState, and
// the provenance: stage, frame, config digest and the rest guides' digest), and the checks a cache
// passes before a simulation resumes from it. A restart state is an input like any other: a cache from
// another configuration, from other rest guides, from an older hairgen, or with values no simulation
// makes (non-finite numbers, a hair stretched past its bound, a velocity past any hair's) is refused
// with InputError naming the file, before anything is stepped.
//
// The layouts, per model:
// - springs: per segment (a strand's points after its root, strand by strand), its end point's
//   position (m), velocity (m/s), velocity a substep before (m/s) and last substep's move over the
//   substep (m/s: the step's history, spring_dynamics.h) in the head's frame, kSpringStateValues doubles.
// - anjyo: a header of kAnjyoStateHeader doubles (kAnjyoStateTag, kAnjyoLanes, kAnjyoStateValues, then
//   zeros), then per block of kAnjyoLanes strands, per segment of the block's longest strand, per value
//   (θ, φ, their turns over the last substep), the block's lanes as floats, two to a double.
//
// This unit reads nothing but its arguments (no physics), so the fuzz build (tests/fuzz) builds it
// with the other readers.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "libcore/config/params.h"
#include "libcore/model/strands.h"

namespace hairgen {

// The bounds every springs state keeps after each substep (spring_dynamics.h checks them there), and
// which a restart state must keep too:
// - a segment is within kMaxSpringStretch of its rest length: the stretch solve holds every bundled
//   shot within 0.1%, so 1% is a solve that did not converge, not hair;
// - a point moves at most kMaxSpringSpeed: three times the speed of sound, far past a whip's crack.
inline constexpr double kMaxSpringStretch = 0.01;
inline constexpr double kMaxSpringSpeed = 1000.0;  // m/s
// Per segment: position, velocity, the velocity before, the last move (12 since the BDF2 step; 6 before,
// which checkStateValues names as an older hairgen's).
inline constexpr size_t kSpringStateValues = 12;

// How a springs segment leaves the bounds above: a position or velocity that is not finite, a stretch
// `value` = length / rest length − 1 past kMaxSpringStretch, or a speed `value` (m/s) past
// kMaxSpringSpeed.
struct SpringSegmentFault {
  enum Kind { kNotFinite, kStretch, kSpeed };
  Kind kind = kNotFinite;
  double value = 0.0;
};
// The bounds above on one segment, the one place they are decided (the simulation after each substep,
// SpringHair::fault(), and a restart state here): the segment from `start` to `end` (metres), whose end
// point moves at `velocity` (m/s) and whose rest length is `restLength` (> 0, metres). Checks finiteness
// of `end` and `velocity`, then the stretch, then the speed; returns the first that fails, or nullopt.
std::optional<SpringSegmentFault> springSegmentFault(const glm::dvec3& start, const glm::dvec3& end,
                                                     const glm::dvec3& velocity, double restLength);
// Throws InputError naming `source` unless a springs state of `values` doubles is for guides of
// `segments` segments (kSpringStateValues a segment); an older hairgen's 6 a segment is named as such.
void requireSpringStateSize(size_t segments, size_t values, const std::string& source);
// The bounds above on a velocity alone (the state's history: a velocity a substep before, a move over a
// substep): not finite, or a speed past kMaxSpringSpeed.
std::optional<SpringSegmentFault> springSpeedFault(const glm::dvec3& velocity);

// Anjyo's layout (anjyo_dynamics.h keeps its state in it) and its bounds: each segment's rotation from
// its rest direction is at most half a turn, and a turn of more than kMaxAnjyoTurn in a substep is no
// shot's.
inline constexpr size_t kAnjyoStateValues = 4, kAnjyoStateHeader = 8, kAnjyoLanes = 16;
inline constexpr double kAnjyoStateTag = 0x414e4a36;  // "ANJ6"
inline constexpr double kMaxAnjyoAngle = 4.0;         // radians
inline constexpr double kMaxAnjyoTurn = 1e3;          // radians a substep

// The doubles an Anjyo state of `rest`'s strand layout holds, header included.
size_t anjyoStateSize(const Strands& rest);

// A digest of the rest guides a simulation starts from (their strand layout, points and tangents): 16
// hex digits, recorded in every simulated frame's provenance (Provenance::restDigest).
std::string restGuidesDigest(const Strands& rest);

// What a resumed simulation expects of the cache of the frame before its first.
struct RestartExpectation {
  DynamicsModel model = DynamicsModel::kAnjyo;
  int frame = 0;             // the frame the cache must be
  std::string configDigest;  // the configuration's digest (Config::digest())
  std::string restDigest;    // restGuidesDigest(rest)
};

// Throws InputError naming `source` unless `cache` is frame `expected.frame` of a simulation of `rest`
// under the same configuration, written by a hairgen that records the rest guides' digest, with a
// restart state of `expected.model`'s layout for `rest`'s strands whose every value is within its
// bounds (above).
void checkRestartState(const Strands& rest, const Strands& cache, const RestartExpectation& expected,
                       const std::string& source);

// The checks of checkRestartState on the state alone (its size, layout and values), for `model`.
void checkStateValues(const Strands& rest, const std::vector<double>& state, DynamicsModel model,
                      const std::string& source);

}  // namespace hairgen
