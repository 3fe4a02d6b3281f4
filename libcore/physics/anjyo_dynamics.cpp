// Anjyo et al. 1992 §3, as anjyo_dynamics.h describes it: the hair set up for the kernel
// (anjyo_kernel.inc), its state, and the substeps run block by block on every core.
#include "libcore/physics/anjyo_dynamics.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <stdexcept>

#include <tbb/parallel_for.h>

#include "libcore/physics/strand_energy.h"
#include "libcore/util/atomic_min.h"
#include "libcore/util/cpu.h"
#include "libcore/util/error.h"
#include "libcore/util/huge_pages.h"

namespace hairgen {
namespace {

// The kernel asked for, or the portable one where this processor has no AVX-512.
AnjyoHair::Kernel available(AnjyoHair::Kernel asked) {
  return asked != AnjyoHair::Kernel::kPortable && hasAvx512() ? AnjyoHair::Kernel::kAvx512
                                                              : AnjyoHair::Kernel::kPortable;
}

void toFloats(const glm::dvec3& v, float (&to)[3]) {
  for (int c = 0; c < 3; ++c) to[c] = float(v[c]);
}

// The auto rest spring of a segment (README, Dynamics), ω² in 1/s²: `coefficient` its c_i u_i m_i (1/m),
// g the gravity (m/s²), kappa sqrt(ρA g / EI) (1/m^1.5), `length` its hair's (m), `from` how far its
// middle is from the root (m), `upward` the rest gravity against its rest direction (−g·rest, m/s²). A
// hanging hair's elastica under its own weight bends in a layer at the root where its slope approaches the
// field's as exp(−∫ds/λ), λ = sqrt(EI/T), T = ρAg(L − s) the weight below; a lone segment held by ω² settles
// at the fraction ω²/(c g + ω²) of its departure, so ω² = c g e/(1 − e) puts it where the elastica's slope
// is. A segment that points upward at rest is given gravity's own stiffness against it besides (its styling
// holds it, as a hair cannot alone).
double restSpring(double coefficient, double g, double kappa, double length, double from, double upward) {
  const double below = std::max(length - from, 0.0);
  const double x = 2.0 / 3.0 * kappa * (length * std::sqrt(length) - below * std::sqrt(below));
  return coefficient * (g / std::expm1(x) + std::max(upward, 0.0));
}

}  // namespace

double firstBendingFrequency(const Hairstyle& style, double length) {
  const double a = style.hairRadius1, b = style.hairRadius2;
  const double inertia = M_PI * a * b * b * b / 4.0, area = M_PI * a * b;
  const double l2 = length * length;
  return 1.875 * 1.875 * std::sqrt(style.young * inertia / (style.massDensity * area * l2 * l2)) /
         (2.0 * M_PI);
}

AnjyoHair::AnjyoHair(const Strands& rest, const Hairstyle& style, const Dynamics& dynamics,
                     const Collision& collision, uint64_t seed)
    : rest_(rest),
      restAcceleration_(0.0, -style.gravity, 0.0),
      damping_(dynamics.damping),
      pseudoAlpha_(dynamics.pseudoAlpha),
      pseudoEpsilon_(dynamics.pseudoEpsilon),
      fluctuation_(dynamics.fluctuation),
      fluctuationEvery_(dynamics.fluctuationEvery),
      firstFrame_(dynamics.firstFrame),
      seed_(seed) {
  const size_t strands = rest.strandCount();
  firstSegment_.assign(strands + 1, 0);
  for (size_t s = 0; s < strands; ++s) {
    if (rest.pointsOf(s) == 0) throw InputError("guide " + std::to_string(s) + " has no points");
    firstSegment_[s + 1] = firstSegment_[s] + rest.pointsOf(s) - 1;
  }
  // Blocks of kLanes strands, each as long as its longest strand.
  const size_t blocks = (strands + kLanes - 1) / kLanes;
  blockFirst_.assign(blocks + 1, 0);
  for (size_t b = 0; b < blocks; ++b) {
    uint32_t most = 0;
    for (size_t s = b * kLanes; s < std::min(strands, (b + 1) * kLanes); ++s)
      most = std::max(most, firstSegment_[s + 1] - firstSegment_[s]);
    blockFirst_[b + 1] = blockFirst_[b] + most;
  }
  // The origin the kernel measures from: the centre of the hair's bounds, where floats are finest.
  if (rest.pointCount() > 0) {
    glm::dvec3 lo(rest.points[0]), hi = lo;
    for (const glm::vec3& p : rest.points) {
      lo = glm::min(lo, glm::dvec3(p));
      hi = glm::max(hi, glm::dvec3(p));
    }
    origin_ = glm::floor(0.5 * (lo + hi) * 1024.0) / 1024.0;  // a round number: exact offsets
  }
  const std::vector<CollisionShape>& shapes = collision.shapes;
  if (const CollisionShape* head = headShape(collision)) head_ = int(head - shapes.data());
  for (const CollisionShape& c : shapes) {
    LaneShape s;
    s.kind = c.kind;
    s.collides = c.penalty > 0.0;
    toFloats(c.centre - origin_, s.centre);
    for (int k = 0; k < 3; ++k) {
      toFloats(c.axes[k], s.axes[k]);
      toFloats(c.axes[k] / c.halfExtents[k], s.scaled[k]);
      s.half[k] = float(c.halfExtents[k]);
    }
    const double radius = boundingRadius(c);
    s.reach2 = float(radius * radius * (1.0 + 1e-5));
    s.slack = float(1e-6 * radius);
    laneShapes_.push_back(s);
  }
  if (head_ >= 0) {
    const glm::dvec3& half = shapes[size_t(head_)].halfExtents;
    pseudoNear2_ =
        float(std::pow(1.0 + std::max(dynamics.pseudoReach, 0.0) / std::min({half.x, half.y, half.z}), 2));
  }

  // At rest every angle is 0. The large arrays are made in huge pages on every core (huge_pages.h), and
  // filled block by block on every core: each block's values depend on its strands alone.
  resizeLarge(state_, kStateHeader + blockFirst_.back() * kStateValues * kLanes / 2);
  std::fill(state_.begin(), state_.begin() + kStateHeader, 0.0);
  state_[0] = kStateTag;
  state_[1] = double(kLanes);
  state_[2] = double(kStateValues);
  resizeLarge(trig_, blockFirst_.back() * kTrigValues);
  blockWithin_.assign(blocks, 0);
  resizeLarge(segments_, blockFirst_.back());
  resizeLarge(points_, blockFirst_.back() + blocks);
  resizeLarge(restDepth_, (blockFirst_.back() + blocks) * laneShapes_.size());
  const PointArray tangents = tangentsOf(rest);
  rest_.points = {};  // posing writes the points and tangents; the rest's are kept lane by lane
  rest_.tangents = {};

  // The points lane by lane (a lane past the last strand repeats the last strand's, a point past a
  // strand's end its last), then each segment's length and each strand's; the first strand with a
  // segment of no length, if any, is refused (the first, whatever the thread count).
  const Kernel kernel = available(Kernel::kFastest);
  std::vector<float> totals(strands, 0.0f);
  std::atomic<size_t> firstBad{strands};
  tbb::parallel_for(size_t(0), blocks, [&](size_t b) {
    const size_t most = blockFirst_[b + 1] - blockFirst_[b];
    for (size_t l = 0; l < kLanes; ++l) {
      const size_t s = std::min(b * kLanes + l, strands - 1);
      const uint32_t p0 = rest.firstPoint[s], last = rest.pointsOf(s) - 1;
      for (size_t j = 0; j <= most; ++j) {
        const size_t p = p0 + std::min<size_t>(j, last);
        LanePoint& to = points_[blockFirst_[b] + b + j];
        for (int c = 0; c < 3; ++c) {
          to.point[c][l] = rest.points[p][c];
          to.tangent[c][l] = tangents[p][c];
        }
      }
      for (int c = 0; c < 3; ++c)  // the root, where the rest nodes start
        points_[blockFirst_[b] + b].forward[c][l] = float(double(rest.points[p0][c]) - origin_[c]);
    }
    Kernels::measure(*this, b, totals.data(), firstBad, kernel);
  });
  if (firstBad < strands) {
    // Its first segment whose length, as the kernel measures it in floats, is not positive.
    const size_t s = firstBad;
    const uint32_t p0 = rest.firstPoint[s];
    uint32_t j = 0;
    for (; j + 2 < rest.pointsOf(s); ++j) {
      const glm::vec3 chord = rest.points[p0 + j + 1] - rest.points[p0 + j];
      if (!(std::sqrt(chord.x * chord.x + chord.y * chord.y + chord.z * chord.z) > 0.0f)) break;
    }
    throw InputError("guide " + std::to_string(s) + " has two points at the same place (points " +
                     std::to_string(j) + " and " + std::to_string(j + 1) +
                     "); a segment needs a length that floats can hold");
  }
  const double jointLimit = glm::radians(style.jointLimit);
  SetupParams params;
  params.totals = totals.data();
  toFloats(restAcceleration_, params.restAcceleration);
  params.cosLimit = float(std::cos(jointLimit));
  params.sinLimit = float(std::sin(jointLimit));
  params.limited = jointLimit < M_PI;
  params.jointFrom = style.jointLimitFrom;
  params.rootSegments = dynamics.rootSegments;
  params.rootInertia = float(dynamics.rootInertia);
  params.inertiaExponent = float(dynamics.inertiaExponent);
  tbb::parallel_for(size_t(0), blocks, [&](size_t b) { Kernels::setup(*this, b, params, kernel); });
  setSprings(style, dynamics, totals);
}

void AnjyoHair::setSprings(const Hairstyle& style, const Dynamics& dynamics,
                           const std::vector<float>& totals) {
  const float longest = totals.empty() ? 0.0f : *std::max_element(totals.begin(), totals.end());
  const double frequency =
      dynamics.restFrequencyAuto ? firstBendingFrequency(style, longest) : dynamics.restFrequency;
  const bool elastica = dynamics.restFrequencyAuto && style.gravity > 0.0;
  const float uniform = float(std::pow(2.0 * M_PI * frequency, 2));
  const double ra = style.hairRadius1, rb = style.hairRadius2;
  const double bending = style.young * M_PI * ra * rb * rb * rb / 4.0,
               linear = style.massDensity * M_PI * ra * rb;
  // ∫₀^s ds'/λ(s') = κ (2/3)(L^1.5 − (L − s)^1.5), λ = sqrt(EI / T) under the weight T = ρA g (L − s') below.
  const double kappa = std::sqrt(linear * style.gravity / bending);
  const size_t strands = rest_.strandCount();
  tbb::parallel_for(size_t(0), blockCount(), [&](size_t b) {
    for (size_t l = 0; l < kLanes && b * kLanes + l < strands; ++l) {
      const size_t s = b * kLanes + l;
      double along = 0.0;
      for (uint32_t j = 0; j < firstSegment_[s + 1] - firstSegment_[s]; ++j) {
        LaneSegment& segment = segments_[blockFirst_[b] + j];
        const double d = segment.length[l];
        const double upward = -restAcceleration_.y * double(segment.rest[1][l]);  // −g·rest, g along −y
        segment.spring[l] = elastica ? float(restSpring(segment.coefficient[l], style.gravity, kappa,
                                                        totals[s], along + 0.5 * d, upward))
                                     : uniform;
        along += d;
      }
    }
  });
}

void AnjyoHair::requireState() const {
  if (state_.size() < kStateHeader)
    throw std::logic_error("AnjyoHair: stepped while its state was lent out (swapState)");
}

bool AnjyoHair::fluctuates(int frame, bool firstSubstep) const {
  return firstSubstep && fluctuation_ > 0.0 && frame > firstFrame_ &&
         (frame - firstFrame_) % fluctuationEvery_ == 0;
}

AnjyoHair::StepParams AnjyoHair::paramsOf(const AccelerationField& field, double dt, int frame,
                                          bool firstSubstep) const {
  StepParams p;
  toFloats(field.base, p.fieldBase);
  toFloats(restAcceleration_, p.restAcceleration);
  toFloats(field.omega, p.omega);
  toFloats(field.alpha, p.alpha);
  toFloats(field.centre - origin_, p.centre);
  p.rotating = field.rotating;
  p.keep = float(std::max(0.0, 1.0 - damping_ * dt));
  p.dt2 = float(dt * dt);
  p.invDt = float(1.0 / dt);
  p.fluctuate = fluctuates(frame, firstSubstep);
  p.fluctuationBlock = p.fluctuate ? uint64_t((frame - firstFrame_) / fluctuationEvery_) : 0;
  return p;
}

void AnjyoHair::step(const AccelerationField& field, double dt, int frame, bool firstSubstep, Kernel kernel) {
  requireState();
  const StepParams params = paramsOf(field, dt, frame, firstSubstep);
  kernel = available(kernel);
  tbb::parallel_for(size_t(0), blockCount(),
                    [&](size_t b) { Kernels::step(*this, b, params, nullptr, nullptr, kernel); });
  stepChecked_ = true;
}

void AnjyoHair::stepAndPose(const AccelerationField& field, double dt, int frame, bool firstSubstep,
                            const Pose& pose, Strands& out, Kernel kernel) {
  requireState();
  const StepParams params = paramsOf(field, dt, frame, firstSubstep);
  kernel = available(kernel);
  out.assignRestKeepingBuffers(rest_);  // every attribute but the points and tangents is the rest's
  tbb::parallel_for(size_t(0), blockCount(),
                    [&](size_t b) { Kernels::step(*this, b, params, &pose, &out, kernel); });
  stepChecked_ = true;
}

Strands AnjyoHair::posed(const Pose& pose) const {
  Strands out;
  posedInto(pose, out);
  return out;
}

void AnjyoHair::posedInto(const Pose& pose, Strands& out, Kernel kernel) const {
  out.assignRestKeepingBuffers(rest_);
  kernel = available(kernel);
  tbb::parallel_for(size_t(0), blockCount(), [&](size_t b) { Kernels::pose(*this, b, pose, out, kernel); });
}

std::vector<glm::dvec3> AnjyoHair::nodes(Kernel kernel) const {
  std::vector<glm::dvec3> out(rest_.firstPoint.back());
  kernel = available(kernel);
  tbb::parallel_for(size_t(0), blockCount(), [&](size_t b) { Kernels::nodes(*this, b, out, kernel); });
  return out;
}

void AnjyoHair::atan2Lanes(const float (&y)[kLanes], const float (&x)[kLanes], float (&out)[kLanes],
                           Kernel kernel) {
  Kernels::atan2(y, x, out, available(kernel));
}

std::array<double, AnjyoHair::kStateValues> AnjyoHair::segmentState(size_t s, uint32_t j) const {
  const float* state = stateAt(blockFirst_[s / kLanes] + j) + s % kLanes;
  std::array<double, kStateValues> out;
  for (size_t v = 0; v < kStateValues; ++v) {
    float value;
    std::memcpy(&value, state + v * kLanes, sizeof(float));
    out[v] = value;
  }
  return out;
}

void AnjyoHair::setSegmentState(size_t s, uint32_t j, const std::array<double, kStateValues>& values) {
  float* state = stateAt(blockFirst_[s / kLanes] + j) + s % kLanes;
  for (size_t v = 0; v < kStateValues; ++v) {
    const float value = float(values[v]);
    std::memcpy(state + v * kLanes, &value, sizeof(float));
  }
  stepChecked_ = false;
  Kernels::angleTrig(*this, s / kLanes, available(Kernel::kFastest));
}

void AnjyoHair::restore(const std::vector<double>& state, const std::string& source) {
  checkStateValues(rest_, state, DynamicsModel::kAnjyo, source);  // rest_ keeps the strand layout
  state_ = state;
  stepChecked_ = false;
  const Kernel kernel = available(Kernel::kFastest);
  tbb::parallel_for(size_t(0), blockCount(), [&](size_t b) { Kernels::angleTrig(*this, b, kernel); });
}

std::optional<AnjyoHair::Fault> AnjyoHair::fault() const {
  requireState();
  // A block's first faulty strand (in strand order, then segment order); the lowest such block of all,
  // found on every core. A lane past its strand's end is not the hair's and is not read.
  const size_t strands = rest_.strandCount();
  auto blockFault = [&](size_t b) -> std::optional<Fault> {
    for (size_t l = 0; l < kLanes && b * kLanes + l < strands; ++l) {
      const size_t s = b * kLanes + l;
      for (uint32_t j = 0; j < firstSegment_[s + 1] - firstSegment_[s]; ++j) {
        const float* values = stateAt(blockFirst_[b] + j) + l;
        for (size_t v = 0; v < kStateValues; ++v)
          if (!(std::abs(values[v * kLanes]) <= (v < 2 ? float(kMaxAngle) : float(kMaxTurn))))
            return Fault{s, j, v < 2, double(values[v * kLanes])};
      }
    }
    return std::nullopt;
  };
  // Every frame checks the whole state. After a step, the step has found the common case, a block wholly
  // within bounds, as it stored the values; otherwise it is one branch-free pass over its contiguous rows
  // (padding lanes included: one out of bounds only sends the block to the exact search above, which skips
  // them). (Counted as integers over fixed-length rows, the angles' and the turns' apart, so that the loops
  // vectorise: a NaN counts as out of bounds.)
  auto blockWithinBounds = [&](size_t b) {
    const float* values = stateAt(blockFirst_[b]);
    const size_t rows = blockFirst_[b + 1] - blockFirst_[b];
    constexpr float kAngle = float(kMaxAngle), kTurn = float(kMaxTurn);
    int outside = 0;
    for (size_t r = 0; r < rows; ++r, values += kStateValues * kLanes) {
      for (size_t i = 0; i < 2 * kLanes; ++i) outside += !(std::abs(values[i]) <= kAngle);
      for (size_t i = 2 * kLanes; i < kStateValues * kLanes; ++i) outside += !(std::abs(values[i]) <= kTurn);
    }
    return outside == 0;
  };
  std::atomic<size_t> first{blockCount()};
  tbb::parallel_for(size_t(0), blockCount(), [&](size_t b) {
    if (b >= first.load(std::memory_order_relaxed) || (stepChecked_ && blockWithin_[b]) ||
        blockWithinBounds(b) || !blockFault(b))
      return;
    atomicMin(first, b);
  });
  if (first == blockCount()) return std::nullopt;
  return blockFault(first);
}

}  // namespace hairgen
