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
// - Angles: the paper measures θ from the vertical. A hanging segment then sits at the pole, where φ is
//   undefined and (5) loses its force, and a small sideways push turns into a spin of φ. hairgen
//   measures each segment's angles in a frame of its own whose pole is perpendicular to the segment's
//   rest direction: the rest is θ = φ = 0 on the equator, where (4) and (5) are exactly the equations of
//   a stick turning about its root, and the pole is 90° of departure away.
// - Units: F is the segment's mass times an acceleration field (gravity, wind, and in the head's frame the
//   head's own acceleration, with the rotating frame's Euler, centrifugal and Coriolis terms). I_i is
//   (k/i)^p m_i d_i L/3 (times a root factor for the first n segments), so c_i u_i m_i = 3 (i/k)^p/(2L):
//   the mass cancels, the tip segment turns like the whole hair as one stick (for one segment, the
//   compound pendulum ρL³/3), toward the root the inertia grows as 1/i, and at a given fraction of the
//   length the response does not depend on how many segments the hair has. (The paper's own
//   normalisation, I_k = ρ(kd)²/3, is k times this: `Inertia 1 k k`.)
// - Rest: the guides were styled under gravity, which the equations alone do not hold. The hair moves by
//   its departure from the styled state: the force is the field minus the styling load (the rest pose's
//   gravity), and an angular spring at RestFrequency pulls each segment toward its rest direction. Still
//   hair (a still head, no wind) therefore stays exactly at rest, a wind or a turn of the head moves it,
//   and a nod moves it as gravity turns in the head's frame.
// - The pseudo-force field (§3.2.2) scales the departure force, not gravity: near the head ellipsoid, a
//   departure pointing into it (D·F < α|D||F|, D the ellipsoid's gradient) is multiplied by ε.
// - Joint limits and collisions are measured against the rest shape: a node may turn as much as it did at
//   rest, and sink as deep into a shape as it sat at rest, so the styled shape is always allowed.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "libcore/config/params.h"
#include "libcore/model/strands.h"
#include "libcore/physics/head_motion.h"

namespace hairgen {

// The frame a segment's angles are measured in: `rest` its rest direction, `pole` perpendicular to it,
// `side` = pole × rest. θ is the latitude toward the pole and φ the longitude from the rest direction,
// so the rest is (0, 0) exactly and sits on the equator.
struct SegmentFrame {
  glm::dvec3 rest, pole, side;
};

class AnjyoHair {
 public:
  // `rest`: the styled guides, in the head's rest pose (the pose the wick and Collision Info describe).
  // Strands of one point stay put. Throws InputError for a strand with no points or a zero-length
  // segment.
  AnjyoHair(const Strands& rest, const Hairstyle& style, const Dynamics& dynamics, const Collision& collision,
            uint64_t seed);

  // How a step is computed; each gives the same bits. kStrands: strand by strand. kLanes: kLanes strands
  // at a time in AVX-512 vectors, where the processor has it (else kStrands), falling back to the
  // strand's arithmetic where a segment meets a shape or its joint limit, and for the frames that draw
  // fluctuations. kFastest: kLanes.
  enum class Kernel { kFastest, kStrands, kLanes };
  static constexpr size_t kLanes = 8;  // strands a vector step takes at once

  // One substep of `dt` seconds for every strand (in parallel; the result does not depend on the
  // thread count or the kernel). `frame` and `firstSubstep` key the fluctuations, drawn at the first
  // substep of every Fluctuation-th frame.
  void step(const AccelerationField& field, double dt, int frame, bool firstSubstep,
            Kernel kernel = Kernel::kFastest);

  // step(), then posedInto(pose, out), in one pass over the hair where the kernel allows (the lanes):
  // the same bits, the hair read once.
  void stepAndPose(const AccelerationField& field, double dt, int frame, bool firstSubstep, const Pose& pose,
                   Strands& out, Kernel kernel = Kernel::kFastest);

  // The current hair in world coordinates: the head frame moved by `pose`. Points at rest are the input
  // points exactly; tangents are the input's, turned with their segment.
  Strands posed(const Pose& pose) const;
  // The same into `out`, reusing its arrays (any kernel gives the same bits).
  void posedInto(const Pose& pose, Strands& out, Kernel kernel = Kernel::kFastest) const;

  // What a restart needs, kStateValues values per segment: θ and φ, and the previous substep's (their sin
  // and cos are computed from them by arithmetic alone, anjyo_sincos.h, so a resumed run computes
  // exactly what the unbroken one did). Laid out as the vector step reads it: a header of kStateHeader
  // values (kStateTag, kLanes, kStateValues, then zeros), then per block of kLanes strands, per
  // segment, per value, the block's lanes (a lane past its strand's end holds the rest state, zeros).
  // The hair keeps its state in this layout, so `swapState` lends it to a frame's cache without a copy:
  // swap it out, write the cache, swap it back (stepping in between is an error).
  static constexpr size_t kStateValues = 4, kStateHeader = 8;
  static constexpr double kStateTag = 0x414e4a33;  // "ANJ3": a state of this layout
  static constexpr double kMaxAngle = 1e5;         // radians: the most a restart state may hold
  std::vector<double> state() const { return state_; }
  void swapState(std::vector<double>& other) { state_.swap(other); }
  void restore(const std::vector<double>& state, const std::string& source);
  // One segment's values (θ, φ, the previous θ, φ), and setting them.
  std::array<double, kStateValues> segmentState(size_t strand, uint32_t j) const;
  void setSegmentState(size_t strand, uint32_t j, const std::array<double, kStateValues>& values);

  size_t segmentCount() const { return firstSegment_.back(); }
  // Diagnostics for tests: every node's position (head frame), and each joint's turn in radians.
  std::vector<glm::dvec3> nodes() const;

 private:
  bool fluctuates(int frame, bool firstSubstep) const;  // whether this substep draws the fluctuations
  void stepStrand(size_t strand, const AccelerationField& field, double dt, int frame, bool fluctuate);
  // The substep of the block of kLanes strands from s0 (anjyo_lanes.cpp): stepStrand's arithmetic lane by
  // lane, bit for bit, in AVX-512 vectors (the processor must have it).
  void stepLanes(size_t s0, const AccelerationField& field, double dt, const Pose* pose = nullptr,
                 Strands* out = nullptr);
  void poseLanes(size_t s0, const Pose& pose, Strands& out) const;  // posedInto's, the same way
  // The new direction `placed` of segment i, from `node` (point nodeIndex − 1) after `before`: out of the
  // collision shapes and within the joint limit; where it moved, the angles are read off it. Returns
  // whether it moved.
  struct Segment;
  bool settle(const Segment& segment, size_t nodeIndex, const glm::dvec3& node, const glm::dvec3& before,
              glm::dvec3& placed, double& theta, double& phi) const;
  glm::dvec3 directionOf(size_t strand, uint32_t j) const;  // segment j's, from its angles
  // Where segment j of `strand` keeps its first value in state_; value v is kLanes further on per v.
  size_t stateAt(size_t strand, uint32_t j) const {
    return kStateHeader + ((blockFirst_[strand / kLanes] + j) * kStateValues) * kLanes + strand % kLanes;
  }

  // What a step reads of a segment: its frame (README, Dynamics), d_i, c_i u_i m_i (1/m), ω² / c_i (the
  // rest spring as an acceleration), and the turn allowed at the node before it (cos −2 where there is
  // no limit). Kept only lane by lane (lanes_); segmentOf gathers one.
  struct Segment {
    SegmentFrame frame;
    double length, coefficient, springOverC, cosAllowed, sinAllowed;
  };
  Segment segmentOf(size_t strand, uint32_t j) const;
  // The state's values of a segment, in the restart layout.
  enum StateValue { kTheta, kPhi, kThetaPrev, kPhiPrev };

  // Segment j of a block of kLanes consecutive strands, lane by lane (a lane past its strand's last
  // segment holds zeros): what stepLanes reads of the segments, laid out for its vectors.
  struct Lanes;  // anjyo_lanes.cpp
  struct LaneSegment {
    double rest[3][kLanes], pole[3][kLanes], side[3][kLanes];
    double length[kLanes], coefficient[kLanes], springOverC[kLanes], cosAllowed[kLanes], sinAllowed[kLanes];
    Segment at(size_t lane) const;  // lane `lane`'s values
    void set(size_t lane, const Segment& segment);
  };
  std::vector<LaneSegment> lanes_;
  std::vector<size_t> blockFirst_;  // per block, its first LaneSegment, + 1
  // Point j of a block's strands, lane by lane (a lane past its strand's last point repeats it): the
  // input point, the rest node and the input tangent that posing starts from (the input's floats, kept
  // as floats: posing reads them once a frame). Block b's points start at blockFirst_[b] + b (one more
  // point than segments per block).
  struct LanePoint {
    float point[3][kLanes];
    double forward[3][kLanes];
    float tangent[3][kLanes];
  };
  std::vector<LanePoint> lanePoints_;

  Strands rest_;  // every attribute of the rest guides but their points and tangents
  PointArray restPoints_;
  std::vector<uint32_t> firstSegment_;  // per strand, + 1
  std::vector<double> state_;           // kStateValues per segment (the restart layout): all 0 at rest
  std::vector<double> shapeReach2_;     // per shape: beyond this squared distance nothing reaches it
  // Per shape, a test cheaper than penetration() that rules out most points (exact for ellipsoids,
  // always "maybe" for the other shapes). `v` is the point less the shape's centre.
  struct ShapeTest {
    bool ellipsoid = false;
    glm::dvec3 scaled[3] = {};  // the axes over the semi-axes
    double near2 = 0.0;  // (1 + PseudoForce reach / smallest semi-axis)²: within the pseudo-force's reach
    double ratio2(const glm::dvec3& v) const {
      const glm::dvec3 r(glm::dot(v, scaled[0]), glm::dot(v, scaled[1]), glm::dot(v, scaled[2]));
      return glm::dot(r, r);
    }
    bool mayBeInside(const glm::dvec3& v) const { return !ellipsoid || ratio2(v) < 1.0; }
    bool mayBeWithin(const glm::dvec3& v) const { return !ellipsoid || ratio2(v) < near2; }
  };
  std::vector<ShapeTest> shapeTests_;
  PointArray restTangents_;
  std::vector<glm::dvec3> restForward_;         // the rest nodes as the forward recurrence computes them
  std::vector<std::vector<double>> restDepth_;  // per shape, per node: the depth it sat at in the shape
  std::vector<CollisionShape> shapes_;
  int head_ = -1;  // the first ellipsoid (the pseudo-force head), an index into shapes_
  glm::dvec3 restAcceleration_;
  double springOmega2_ = 0.0, damping_ = 0.0;
  double jointLimit_ = M_PI;  // radians
  int jointFrom_ = 1;
  double pseudoAlpha_, pseudoEpsilon_, pseudoReach_;
  double fluctuation_;
  int fluctuationEvery_, firstFrame_;
  uint64_t seed_;
};

// The first bending mode of a clamped hair, Hz: 1.875² sqrt(E I / (ρ A L⁴)) / 2π, I = π a b³/4, A = π a b.
double firstBendingFrequency(const Hairstyle& style, double length);

}  // namespace hairgen
