// Petrovic, Henne and Anderson 2006, "Volumetric Methods for Simulation and Rendering of Hair" (Pixar
// Technical Memo 06-08) §5: keyhairs as point masses joined by springs (§5 opening), hair-hair
// interaction by smoothing the particles' velocities on the density grid of the memo's (1) (§5.1), and a
// weak force that pushes the hair toward the density of a target shape, −∂E/∂P for E = ½ Σ (D_s − D_t)²
// (§5.2, the memo's (3) and the force after it).
//
// Units: SI (metres, kilograms, seconds). The hair lives in the head's frame, where the roots and the
// collision shapes stand still and AccelerationField gives gravity, the wind and the moving frame's
// terms (libcore/physics/head_motion.h); posedInto() carries it to the world.
//
// The model (README, "Volumetric dynamics (Model springs)"):
// - Particles: every guide point, mass ρ·πab times half of each segment beside it; the root is fixed to
//   the head.
// - Stretch: each segment keeps its length with compliance l/(E·A) (XPBD), solved per strand by a few
//   Newton steps on the tridiagonal system of all its segments at once, so a strand is as stiff at its
//   tip as at its root (no Gauss-Seidel lag along 32 particles).
// - Bending: a spring per joint on its turn vector b_j = e_{j+1}/l_{j+1} − e_j/l_j (the root joint turns
//   the first segment against the head-fixed root direction: a clamp), energy ½ k_j |b_j − b̄_j|² with
//   k_j = E·I / l̄_j (l̄ the joint's share of length), which is the rod's ½ E·I κ² l̄ for small turns.
//   Linear in the positions, as is the rest tension's force −T_j e_j / l_j: both are implicit in a step of
//   the second-order backward difference (BDF2, below), which needs one constant pentadiagonal matrix
//   M(1 + ⅔c·Δt) + (4/9)·Δt²·K per strand, factored once. Gravity, wind and the frame's terms are
//   explicit, stretch and twist projections.
// - Twist: a spring between points i and i + 3 (the classic torsion spring of mass-spring hair), whose
//   length changes with the twist of the middle segment; its stiffness makes the rod's ½ G·J ψ²/l for a
//   twist ψ, so it acts only where the rest shape bends out of a plane (a straight or planar hair has no
//   twist to lose at first order). Solved with the stretch constraints, with compliance.
// - Rest (sag-free): the groomed guides are made an equilibrium of the rest load (gravity along −y at the
//   shot's Gravity). A tip-to-root pass gives every segment the tension that carries the load below it
//   along its length (an explicit force that turns with the segment), and the remainder, across the
//   hair, is carried by the bending springs: their targets b̄ solve Bᵀ diag(k) (b̄ − B x_rest) = load,
//   which is triangular and solved from the tip. The rest is exactly still under a still head.
// - Collisions (§5): particle by particle, each pushed out of every Collision Info shape (with a
//   penalty) to the depth it sat at in the rest shape (so the groomed shape is always allowed).
// - Velocity smoothing (§5.1): masses and momenta of the free particles are splatted with the tent
//   weights of (1) onto a grid, both filtered by the symmetric, doubly stochastic [1 2 1]/4 kernel S,
//   the grid velocity is the filtered momentum over the filtered mass, filtered once more and read back
//   at every particle with the same tent weights; each particle then moves the fraction s of the way to
//   it. As a map on the velocities this is (1 − s)I + s·A with A = Wᵀ S D⁻¹ S W M self-adjoint in the
//   mass inner product with eigenvalues in [0, 1] (README), so it never raises the kinetic energy.
// - Density targeting (§5.2): the target's points (scaled to the hair's point count) and the hair's are
//   splatted on fixed grids per spacing: eight of them, the same grid shifted by half a cell along every
//   combination of axes, and E is the mean of the eight grids' energies (one grid's E depends on where
//   its cell walls fall; the mean much less). A particle's acceleration is DensityStrength times the
//   mean of the eight grids' memo's F (densityForce in libcore/volume/density_target.h), so −∂E/∂P, over
//   the target's mean density where it has any, so the strength means the same on every grid: the
//   acceleration of a point where the density is wrong by the target's mean from one node to the next.
//   Spacings go from coarse to fine: at each frame the hair uses the finest spacing all of whose
//   coarser ones have fallen to DensityRefine of their starting energy (a rule of the present state,
//   so a restart needs nothing more).
//
// Guarantees: a step depends only on the state (positions, velocities and the step's history, in doubles) and
// the inputs; strands step in parallel and every grid sums in a fixed order, so the result is the same bits
// for any thread count, and a run resumed from state() is the same bits as one that never stopped.
#pragma once

#include <atomic>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "libcore/config/params.h"
#include "libcore/io/restart_state.h"
#include "libcore/model/strands.h"
#include "libcore/physics/head_motion.h"
#include "libcore/volume/density_target.h"
#include "libcore/volume/splat.h"

namespace hairgen {

// The stiffnesses the springs get: the Dynamics keys, or from Young, Poisson and the cross-section.
struct SpringStiffness {
  double stretch = 0.0;  // N, E·A
  double bend = 0.0;     // N·m², E·I
  double twist = 0.0;    // N·m², G·J
};
SpringStiffness springStiffness(const Hairstyle& style, const Dynamics& dynamics);

// The gravity a shot's hair feels (N/kg): Dynamics Gravity, or Hairstyle's when auto.
double dynamicsGravity(const Hairstyle& style, const Dynamics& dynamics);

class SpringHair {
 public:
  // `rest`: the groomed guides, in the head's rest pose (the pose the wick and Collision Info describe).
  // `densityTarget`: the target shape of §5.2 in the same frame, or null (then DensityStrength is
  // ignored). Strands of one point stay put. Throws InputError for a segment of zero length.
  SpringHair(const Strands& rest, const Hairstyle& style, const Dynamics& dynamics,
             const Collision& collision, const Strands* densityTarget);

  // One substep of `dt` seconds for every strand. At the first substep of a frame the density spacing
  // is chosen; after the last (`lastSubstep`) the velocities are smoothed by VelocitySmoothing.
  // How a substep is computed; each gives the same bits. kStrands: strand by strand. kLanes: kLanes
  // strands at once in AVX-512 vectors (spring_lanes.cpp), where the processor has it (else kStrands).
  // kFastest: kLanes.
  enum class Kernel { kFastest, kStrands, kLanes };
  static constexpr size_t kLanes = 8;
  static constexpr uint32_t kMaxLaneSegments = 128;  // longer strands step on their own
  // After the substep every strand's state is checked against the bounds of a valid state
  // (libcore/io/restart_state.h: finite, every segment within kMaxSpringStretch of its rest length,
  // every point slower than kMaxSpringSpeed, and so is the step's history), and again after a frame's
  // velocity smoothing; the first strand that left them is kept as fault(), and
  // from then on step() does nothing (nothing computes on nonsense) until restore().
  void step(const AccelerationField& field, double dt, bool firstSubstep, bool lastSubstep,
            Kernel kernel = Kernel::kFastest);

  // How a state left its validity (kind and value: restart_state.h's SpringSegmentFault) at strand
  // `strand`, point `point` (of the strand, 1 = the end of its first segment).
  struct Fault : SpringSegmentFault {
    size_t strand = 0;
    uint32_t point = 0;
  };
  // The first strand (in strand order, whatever the threads) whose state a step left invalid; none while
  // the hair is valid.
  const std::optional<Fault>& fault() const { return fault_; }

  // §5.1 on the current velocities: every free particle moves `fraction` of the way to the smoothed
  // grid velocity at its place. Never raises the kinetic energy.
  void smoothVelocities(double fraction);

  // The hair in world coordinates: the head frame moved by `pose`. At rest the input points exactly;
  // tangents are the input's turned with their segment.
  Strands posed(const Pose& pose) const;
  // (kLanes: each strand's points eight at a time in vectors, the same bits.)
  void posedInto(const Pose& pose, Strands& out, Kernel kernel = Kernel::kFastest) const;

  // What a restart needs: per segment, its end point's position, velocity, velocity a substep before
  // and last move (the step's w) in the head's frame (kStateValues doubles; the roots are the head's);
  // and the inverse.
  // restore() throws InputError naming `source` for a state of another size, or one whose values leave
  // the bounds step() keeps (fault()).
  static constexpr size_t kStateValues = kSpringStateValues;
  std::vector<double> state() const;
  void stateInto(std::vector<double>& out) const;
  void restore(const std::vector<double>& state, const std::string& source);

  // Diagnostics (head frame): per point.
  const std::vector<glm::dvec3>& positions() const { return x_; }
  const std::vector<glm::dvec3>& velocities() const { return v_; }
  std::vector<glm::dvec3>& velocities() { return v_; }  // for tests of smoothVelocities
  // Sets every point's velocity as a motion that has gone on for a while (v⁻ and w the same), for tests.
  void setMotion(const std::vector<glm::dvec3>& v);
  void setPositions(const std::vector<glm::dvec3>& x) { x_ = x; }
  const std::vector<double>& masses() const { return mass_; }
  double kineticEnergy() const;  // joules, summed in point order
  // §5.2: E = ½ Σ (D_s − D_t)² of the current positions on the grids of spacing `level` (0 = coarsest),
  // the mean over its eight half-cell shifts;
  // the level the last frame used; the number of levels (0 without a target).
  double densityEnergy(size_t level) const;
  size_t densityLevel() const { return level_; }
  size_t densityLevels() const { return targets_.size(); }
  // The largest |segment length / rest length − 1| now.
  double maxStretch() const;

 private:
  // A substep of one strand: predict (the explicit forces and the implicit bending into x_, the old
  // positions into `before`, n + 1 of them), projectStretch, constrain (twist springs and collisions;
  // whether they moved a point), projectStretch again where they did, finish (the velocities).
  void stepStrand(size_t strand, const AccelerationField& field, double dt);
  // Strand s's state against the bounds of fault(): the first point that leaves them, if any.
  std::optional<Fault> checkStrand(size_t strand) const;
  // The first strand of [s0, s1) whose checkStrand fails, into `first` (the lowest of all callers).
  void checkStrands(size_t s0, size_t s1, std::atomic<size_t>& first) const;
  // checkStrand's fault of the first strand that fails it (in strand order), on every thread.
  std::optional<Fault> firstFault() const;
  void predict(size_t strand, const AccelerationField& field, double dt, glm::dvec3* before);
  bool constrain(size_t strand, double dt);
  // Point p at `x` out of collision shape c to the depth it sat at in the rest shape; whether it moved.
  bool collide(size_t c, uint32_t p, glm::dvec3& x) const;
  void finish(size_t strand, double dt, const glm::dvec3* before);
  // stepStrand for the strands s0 .. s0 + kLanes − 1: those of the first one's segment count (at most
  // kMaxLaneSegments) together in vectors (spring_lanes.cpp), the others on their own.
  void stepBlock(size_t s0, const AccelerationField& field, double dt);
  // The strands of block s0 / kLanes that step in vectors (into `lanes`, their count returned) and their
  // segment count n: those with as many segments as the block's first strand of 1 to kMaxLaneSegments.
  // The block's other strands step on their own.
  size_t blockLanes(size_t s0, size_t* lanes, uint32_t& n) const;
  // stepStrand for the `count` strands `strands` of block `block` (blockLanes') at once, lane by lane the
  // same bits. Not with density targeting (its forces are read strand by strand).
  void stepLanes(size_t block, const size_t* strands, size_t count, uint32_t n,
                 const AccelerationField& field, double dt);
  // projectStretch(s, dt, 1, zeros) for those of the strands whose `take` is set.
  void projectStretchLanes(size_t block, const size_t* strands, size_t count, uint32_t n, double dt,
                           const bool* take);
  // posedInto's points j0 .. j0 + 7 of strand s, each of which starts a segment (j0 + 8 < its count).
  void poseEightLanes(size_t s, uint32_t j0, const Pose& pose, Strands& out) const;
  // The step is the second-order backward difference (BDF2) in positions and velocities,
  //   x⁺ = x + (Δt/3)·w + (2/3)·Δt·v⁺,
  //   (M(1 + ⅔cΔt) + (4/9)Δt²K) v⁺ = M(4/3·v − 1/3·v⁻) + (2/3)Δt f(x + (Δt/3)·w),
  // with w = (x − x⁻)/Δt, the last substep's move (so x⁺ = 4/3·x − 1/3·x⁻ + (2/3)Δt·v⁺), then the
  // projections, and v⁺ = (3x⁺ − 4x + x⁻)/(2Δt) from the projected points. L-stable: a mode far faster
  // than the step (the bending of millimetre segments, the string modes of a long chain) is gone within a
  // step instead of ringing at the step's own frequency, where a projection's nonlinearity would feed it
  // into a fold; a slow mode keeps its amplitude to second order in the forces taken implicitly (a 10 cm
  // hair's swing at 4 substeps of 24 frames/s: 0.993 a period). Gravity, wind, the frame's terms and the
  // density force are taken at the substep's start and the current state: first order in how they change
  // in time, as before. docs/dynamics-springs.md has the measurements.
  static constexpr double kOneThird = 1.0 / 3.0, kTwoThirds = 2.0 / 3.0, kFourThirds = 4.0 / 3.0,
                          kThreeHalves = 1.5;
  struct Lanes;
  // What the vector kernel reads of every point, lane by lane, so it loads a vector where the strands'
  // own arrays would need eight loads: block by block (laneFirst_), points 0..n of the block's lanes; a
  // lane without a strand repeats the first lane's (112 bytes a point in a full block). Built by
  // factor() where the processor has AVX-512.
  struct LanePoint {
    double mass[kLanes], inverseMass[kLanes], length[kLanes], compliance[kLanes], restTension[kLanes],
        bend[kLanes], lower1[kLanes], lower2[kLanes], inverseD[kLanes], twistLength[kLanes],
        twistCompliance[kLanes], target[3][kLanes];
  };
  std::vector<LanePoint> lanePoints_;
  std::vector<size_t> laneFirst_;  // per block its first LanePoint, and their count last
  void buildLanePoints();
  void factor(double dt);
  void projectStretch(size_t strand, double dt, int iterations, std::vector<double>& lambda);
  std::vector<Grid> densityDifference(size_t level) const;  // D_s − D_t at the current positions
  std::vector<glm::vec3> floatPoints() const;

  Strands rest_;  // every attribute of the rest guides but their points and tangents
  std::vector<glm::dvec3> xRest_, x_, v_;
  // BDF2's history, per point: the velocity a substep before (v⁻) and the last substep's move over Δt (w).
  std::vector<glm::dvec3> previousV_, lastMove_;
  std::vector<double> mass_, inverseMass_;
  // Per segment, indexed by its end point: rest length, stretch compliance l/(E·A) (m/N), rest tension
  // (N, the load below it along its length).
  std::vector<double> length_, compliance_, restTension_;
  // Per joint, indexed by its point (the root's joint turns the first segment against the root
  // direction): stiffness E·I/l̄ (N·m) and target turn vector b̄.
  std::vector<double> bend_;
  std::vector<glm::dvec3> target_;
  std::vector<glm::dvec3> rootDirection_;  // per strand, head frame
  // Twist springs, indexed by their first point i (to i + 3): rest distance and compliance (m/N), 0
  // stiffness as compliance < 0.
  std::vector<double> twistLength_, twistCompliance_;
  PointArray restTangents_;
  std::vector<glm::dvec3> restUnit_;  // per point but each strand's last, its segment's rest direction
  // The implicit solve, per free point: 1/D and the two sub-diagonals of L in M(1 + ⅔cΔt) + (4/9)Δt²K = L D
  // Lᵀ, for the step dt_.
  std::vector<double> inverseD_, lower1_, lower2_;
  double dt_ = 0.0;
  // Collisions: the shapes that collide and per shape the depth every point sat at (at least 0).
  std::vector<CollisionShape> shapes_;
  std::vector<std::vector<double>> restDepth_;
  std::vector<double> shapeReach2_;
  double damping_ = 0.0, smoothing_ = 0.0, smoothingSpacing_ = 0.01;
  // Density targeting: per level the target's density on that level's eight shifted grids; their
  // energies at the start; the strength, the refine fraction and the level in use.
  std::vector<std::vector<Grid>> targets_;
  std::vector<double> startEnergy_;
  std::vector<double> targetMean_;  // per level, the target's mean density over the nodes it occupies
  double densityStrength_ = 0.0, densityRefine_ = 0.5;
  size_t level_ = 0;
  std::vector<Grid> difference_;  // D_s − D_t of the current substep, at level_
  std::optional<Fault> fault_;
  // Velocity smoothing's grid and point lists, kept between frames so their memory is reused.
  GridOf<glm::dvec4> velocityGrid_;
  std::vector<glm::dvec3> smoothWhere_;
  std::vector<glm::dvec4> smoothWhat_;
  std::vector<size_t> smoothWhich_;
  SplatEntries<glm::dvec4> smoothSorted_;
};

}  // namespace hairgen
