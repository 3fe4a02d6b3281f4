// Anjyo, Usami and Kurihara 1992 §3: hair dynamics as one-dimensional projective equations. Each hair
// is a chain of rigid segments from its root; segment i has a polar angle θ_i and an azimuth φ_i, and
//   θ_i'' = c_i u_i F_θ        (4)       φ_i'' = c_i v_i F_φ        (5)
// with c_i = 1/I_i, u_i = |s_i|/2, v_i = the half length of s_i's projection on the horizontal plane, and
// F_θ, F_φ the force's components perpendicular to s_i in the θ and φ planes. They are solved by the
// paper's second-order recurrences (4)' and (5)' (Störmer-Verlet), segment by segment from the root, each
// segment placed from the one before; then, at each node, the joint angle is limited (§3.2.3) and the node
// is kept out of the collision shapes.
//
// hairgen's choices where the paper is open (README, Dynamics):
// - Angles: the paper measures θ from the vertical; a hanging segment then sits at the pole, where φ is
//   undefined, and (4) and (5) as written are a stick turning about its root only on the equator (off
//   it they lose the terms that keep a swing in its plane). hairgen keeps each segment's rotation vector
//   from its rest direction, (a, b) along `pole` and `side`, and measures its turn in the rest frame
//   carried to it by that rotation: re-centred on the segment every substep, where (4) and (5) are the
//   same in every direction. Only the fold straight back (half a turn) is singular.
// - Units: F is the segment's mass times an acceleration field (gravity, wind, and in the head's frame the
//   head's own acceleration, with the rotating frame's Euler, centrifugal and Coriolis terms). I_i is
//   (k/i)^p m_i d_i L/3 (times a root factor for the first n segments), so c_i u_i m_i = 3 (i/k)^p/(2L):
//   the mass cancels, the tip segment turns like the whole hair as one stick (for one segment, the
//   compound pendulum ρL³/3), toward the root the inertia grows as 1/i, and at a given fraction of the
//   length the response does not depend on how many segments the hair has. (The paper's own
//   normalisation, I_k = ρ(kd)²/3, is k times this: `Inertia 1 k k`.)
// - Rest: the guides were styled under gravity, which the equations alone do not hold. Gravity acts whole
//   on the moving hair, its torque following the segment; the styled shape is held by the styling load,
//   the rest pose's gravity across each segment carried with it as a constant torque in its own frame,
//   and an angular spring −ω_i²ψ toward the rest direction (RestFrequency; auto: the stiffness the
//   hanging elastica of the hair's EI gives each place, anjyo_dynamics.cpp's restSpring). Still hair (a
//   still head, no wind) therefore stays exactly at rest; wind, a turn of the head and a nod move it, and
//   gravity pulls it back.
// - The pseudo-force field (§3.2.2) scales the field's departure from the rest's gravity: near the head
//   (headShape), a departure pointing into it (D·F < α|D||F|, D the head's gradient) is multiplied by ε.
// - Joint limits and collisions are measured against the rest shape: a node may turn as much as it did at
//   rest, and sink as deep into a shape as it sat at rest, so the styled shape is always allowed.
// - Precision: everything is floats, the precision the caches store, sixteen strands at a time
//   (anjyo_kernel.inc). The recurrences are velocity Verlet: each segment keeps its rotation (at most half
//   a turn) and its turn over the last substep, so the turn keeps its own precision. Positions are
//   kept relative to the centre of the rest hair's bounds, where a float resolves a tenth of a
//   micrometre on a head.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <optional>
#include <vector>

#include <glm/glm.hpp>

#include "libcore/config/params.h"
#include "libcore/io/restart_state.h"
#include "libcore/model/strands.h"
#include "libcore/physics/head_motion.h"
#include "libcore/util/uninitialised.h"

namespace hairgen {

class AnjyoHair {
 public:
  // `rest`: the styled guides, in the head's rest pose (the pose the wick and Collision Info describe).
  // Strands of one point stay put. Throws InputError for a strand with no points or a zero-length
  // segment.
  AnjyoHair(const Strands& rest, const Hairstyle& style, const Dynamics& dynamics, const Collision& collision,
            uint64_t seed);

  // The builds of the step (anjyo_kernel.inc), which give the same bits: kPortable for any x86-64, kAvx512
  // where the processor has AVX-512 (else kPortable). kFastest: the fastest this processor runs.
  enum class Kernel { kFastest, kPortable, kAvx512 };
  static constexpr size_t kLanes = 16;  // strands a step takes at once
  static_assert(kLanes == kAnjyoLanes, "the restart layout's lanes are the step's");

  // One substep of `dt` seconds for every strand (in parallel; the result depends on neither the thread
  // count nor the kernel). `frame` and `firstSubstep` key the fluctuations, drawn at the first substep of
  // every Fluctuation-th frame.
  void step(const AccelerationField& field, double dt, int frame, bool firstSubstep,
            Kernel kernel = Kernel::kFastest);

  // step(), then posedInto(pose, out), in one pass over the hair: the same bits, the hair read once.
  void stepAndPose(const AccelerationField& field, double dt, int frame, bool firstSubstep, const Pose& pose,
                   Strands& out, Kernel kernel = Kernel::kFastest);

  // The current hair in world coordinates: the head frame moved by `pose`. Points at rest are the input
  // points exactly; tangents are the input's, turned with their segment.
  Strands posed(const Pose& pose) const;
  // The same into `out`, reusing its arrays.
  void posedInto(const Pose& pose, Strands& out, Kernel kernel = Kernel::kFastest) const;

  // What a restart needs, kStateValues floats per segment: its rotation vector from rest (a, b), and its
  // turn over the last substep in the carried frame (the velocity Verlet's; the trigonometry of the
  // rotation is computed from them by arithmetic alone, anjyo_kernel.inc, so a resumed run computes exactly
  // what the unbroken one did). Laid out as the step reads it: a header of kStateHeader doubles (kStateTag,
  // kLanes, kStateValues, then zeros), then per block of kLanes strands, per segment, per value, the block's
  // lanes as floats, two to a double (a lane past its strand's end holds the rest state, zeros). The hair
  // keeps its state in this layout, so `swapState` lends it to a frame's cache without a copy: swap it out,
  // write the cache, swap it back (stepping in between is an error). (The layout and its bounds are declared
  // once, in libcore/io/restart_state.h.)
  static constexpr size_t kStateValues = kAnjyoStateValues, kStateHeader = kAnjyoStateHeader;
  static constexpr double kStateTag = kAnjyoStateTag;  // "ANJ6": a state of this layout
  static constexpr double kMaxAngle = kMaxAnjyoAngle;  // radians: the most an angle of a state may be
  static constexpr double kMaxTurn = kMaxAnjyoTurn;    // radians: the most its turn in a substep may be
  std::vector<double> state() const { return state_; }
  void swapState(std::vector<double>& other) {
    state_.swap(other);
    stepChecked_ = false;
  }
  // Throws InputError naming `source` for a state of another layout or size, or a value past the bounds.
  void restore(const std::vector<double>& state, const std::string& source);

  // How the state left its validity (a step that overflowed): strand `strand`'s segment `segment`
  // (0 = the root's) holds an angle or a turn (`angle`) of `value` rad that is not finite or past
  // kMaxAngle / kMaxTurn. The first such strand in strand order, or none while the state is valid.
  struct Fault {
    size_t strand = 0;
    uint32_t segment = 0;
    bool angle = true;
    double value = 0.0;
  };
  std::optional<Fault> fault() const;
  // One segment's values (a, b, and the turn over the last substep along the carried pole and side), and
  // setting them: segment j < the strand's segments, strand < the guides'.
  std::array<double, kStateValues> segmentState(size_t strand, uint32_t j) const;
  void setSegmentState(size_t strand, uint32_t j, const std::array<double, kStateValues>& values);

  size_t segmentCount() const { return firstSegment_.back(); }
  // The kernel's atan2 (which reads a moved segment's angles back) on kLanes pairs, for its tests.
  static void atan2Lanes(const float (&y)[kLanes], const float (&x)[kLanes], float (&out)[kLanes],
                         Kernel kernel = Kernel::kFastest);
  // Every node's position in the head frame, as the step computes them (in floats), point by point.
  std::vector<glm::dvec3> nodes(Kernel kernel = Kernel::kFastest) const;

 private:
  // Segment j of a block of kLanes consecutive strands, lane by lane (a lane past its strand's last
  // segment holds zeros): its frame (`rest` its rest direction, `pole` perpendicular to it; the third
  // axis, side = pole × rest, and the styling load, the rest's gravity along pole and side, are computed
  // where they are used: the step reads less memory), d_i, c_i u_i m_i (1/m), the rest spring's ω_i²
  // (1/s²), and the turn allowed at the node before it (cos −2 where there is no limit).
  // (The lane-by-lane arrays are aligned to a cache line, 64 bytes, so each vector the kernel loads or
  // stores is one line, not two.)
  struct alignas(64) LaneSegment {
    float rest[3][kLanes], pole[3][kLanes];
    float length[kLanes], coefficient[kLanes], spring[kLanes];
    float cosAllowed[kLanes], sinAllowed[kLanes];
  };
  // Point j of a block's strands, lane by lane (a lane past its strand's last point repeats it): the
  // input point and tangent that posing starts from, and the rest node as the step computes it (relative
  // to origin_).
  struct alignas(64) LanePoint {
    float point[3][kLanes], forward[3][kLanes], tangent[3][kLanes];
  };
  // A collision shape as the kernel reads it, relative to origin_: its axes over its semi-axes for an
  // ellipsoid (`scaled`), the squared distance from its centre beyond which no point touches it
  // (`reach2`), and `slack`, how much deeper than at rest a node may sit before it is turned out (a
  // millionth of the shape's size: a few float roundings, not contact).
  // kLanes floats, a row of the lane-by-lane arrays of floats (trig_, restDepth_).
  struct alignas(64) LaneRow {
    float lane[kLanes];
  };
  struct LaneShape {
    ShapeKind kind = ShapeKind::kSphere;
    bool collides = false;  // a shape without penalty does not collide, as in grow
    float centre[3] = {}, axes[3][3] = {}, half[3] = {}, scaled[3][3] = {};
    float reach2 = 0.0f, slack = 0.0f;
  };
  // What a substep reads besides the hair: the field in floats (relative to origin_), the recurrences'
  // constants, and the fluctuations' key.
  struct StepParams {
    float fieldBase[3], restAcceleration[3], omega[3], alpha[3], centre[3];
    bool rotating = false, fluctuate = false;
    float keep = 1.0f, dt2 = 0.0f, invDt = 0.0f;
    uint64_t fluctuationBlock = 0;
  };
  // What setup needs besides the hair: each strand's length (per strand), the rest's gravity (m/s², head
  // frame), the joint limit, and the inertia's arrangement (Dynamics Info's Inertia).
  struct SetupParams {
    const float* totals;
    float restAcceleration[3];
    float cosLimit, sinLimit;
    bool limited;  // a JointAngleLimit below 180°
    int jointFrom, rootSegments;
    float rootInertia, inertiaExponent;
  };
  // The kernel (anjyo_kernel.inc), one block of kLanes strands a call, built for any x86-64 and for
  // AVX-512 (anjyo_lanes.cpp): measure and setup fill the segments, rest nodes and depths once the points
  // are filled; step takes a substep (and poses it into `out` where given); pose and nodes read the
  // state; angleTrig finds the sin and cos of a restored state's angles.
  struct Kernels {
    struct Portable;  // the kernel built for any x86-64 (anjyo_kernel.inc)

    struct Avx512;  // and for AVX-512
    static void measure(AnjyoHair& hair, size_t block, float* totals, std::atomic<size_t>& firstBad,
                        Kernel kernel);
    static void setup(AnjyoHair& hair, size_t block, const SetupParams& params, Kernel kernel);
    static void angleTrig(AnjyoHair& hair, size_t block, Kernel kernel);
    static void step(AnjyoHair& hair, size_t block, const StepParams& params, const Pose* pose, Strands* out,
                     Kernel kernel);
    static void pose(const AnjyoHair& hair, size_t block, const Pose& pose, Strands& out, Kernel kernel);
    static void nodes(const AnjyoHair& hair, size_t block, std::vector<glm::dvec3>& out, Kernel kernel);
    static void atan2(const float* y, const float* x, float* out, Kernel kernel);
    static constexpr uint64_t kFluctuationKey = 0x666c756374ull;  // "fluct": apart from every other stream
  };
  // A segment's values in the state: its rotation vector from the rest direction, (a, b) along pole
  // and side, and its turn over the last substep in the frame carried from the rest frame.
  enum StateValue { kAngleA, kAngleB, kTurnA, kTurnB };
  // Of ψ = |(a, b)|, as the step computed them (anjyo_kernel.inc's trigOf): cos ψ, sin ψ / ψ, (1 − cos ψ) /
  // ψ² and ψ, kept beside the state so that a step computes them once: per block, per segment, per value, the
  // lanes.
  static constexpr size_t kTrigValues = 4;
  enum TrigValue { kCosPsi, kSinc, kVersine, kPsi };

  // Each segment's rest spring (README, Dynamics: RestFrequency, or auto), after setup; `totals` per
  // strand, its length.
  void setSprings(const Hairstyle& style, const Dynamics& dynamics, const std::vector<float>& totals);
  bool fluctuates(int frame, bool firstSubstep) const;  // whether this substep draws the fluctuations
  void requireState() const;  // throws std::logic_error while the state is lent out (swapState)
  StepParams paramsOf(const AccelerationField& field, double dt, int frame, bool firstSubstep) const;
  size_t blockCount() const { return blockFirst_.size() - 1; }
  // Block segment i's state, its values' lanes one after the other (floats in state_'s doubles).
  float* stateAt(size_t i) {
    return reinterpret_cast<float*>(state_.data() + kStateHeader) + i * kStateValues * kLanes;
  }
  const float* stateAt(size_t i) const {
    return reinterpret_cast<const float*>(state_.data() + kStateHeader) + i * kStateValues * kLanes;
  }

  // The first float of trig_ and of restDepth_.
  float* trigFloats() { return reinterpret_cast<float*>(trig_.data()); }
  const float* trigFloats() const { return reinterpret_cast<const float*>(trig_.data()); }
  float* restDepthFloats() { return reinterpret_cast<float*>(restDepth_.data()); }
  const float* restDepthFloats() const { return reinterpret_cast<const float*>(restDepth_.data()); }

  // The kernel's arrays, written whole by the constructor (UninitialisedAllocator: not zeroed first).
  std::vector<LaneSegment, UninitialisedAllocator<LaneSegment>> segments_;  // per block, blockFirst_[b] on
  std::vector<size_t> blockFirst_;  // per block, its first LaneSegment, + 1
  // Per block, blockFirst_[b] + b on (one more point than segments).
  std::vector<LanePoint, UninitialisedAllocator<LanePoint>> points_;
  // Per block point, per shape, kLanes: how deep it sat at rest (≥ 0).
  std::vector<LaneRow, UninitialisedAllocator<LaneRow>> restDepth_;
  std::vector<LaneShape> laneShapes_;

  Strands rest_;                        // every attribute of the rest guides but their points and tangents
  std::vector<uint32_t> firstSegment_;  // per strand, + 1
  std::vector<double> state_;           // kStateValues per segment (the restart layout): all 0 at rest
  // Per block, whether the last step left every value of its state within bounds (fault(), padding lanes
  // included), which the step finds as it stores them; read only while stepChecked_ (the state is the
  // last step's: no restore, swap or set since).
  std::vector<char> blockWithin_;
  bool stepChecked_ = false;
  std::vector<LaneRow, UninitialisedAllocator<LaneRow>> trig_;  // kTrigValues per segment: of state_'s angles
  glm::dvec3 origin_{0.0};                                      // the centre of the rest hair's bounds
  int head_ = -1;  // headShape (the pseudo-force head), an index into shapes; -1 for none
  glm::dvec3 restAcceleration_;
  double damping_ = 0.0;
  double pseudoAlpha_, pseudoEpsilon_;
  float pseudoNear2_ = 0.0f;  // (1 + PseudoForce reach / smallest semi-axis)²: within its reach
  double fluctuation_;
  int fluctuationEvery_, firstFrame_;
  uint64_t seed_;
};

// The first bending mode of a clamped hair, Hz: 1.875² sqrt(E I / (ρ A L⁴)) / 2π, I = π a b³/4, A = π a b.
double firstBendingFrequency(const Hairstyle& style, double length);

}  // namespace hairgen
