// Petrovic et al. 2006 §5, as spring_dynamics.h describes it.
#include "libcore/physics/spring_dynamics.h"
#include "libcore/model/strand_frames.h"
#include "libcore/util/cpu.h"

#include <algorithm>
#include <cmath>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include "libcore/io/restart_state.h"
#include "libcore/physics/strand_energy.h"
#include "libcore/physics/tridiagonal.h"
#include "libcore/util/atomic_min.h"
#include "libcore/util/error.h"
#include "libcore/util/text.h"

namespace hairgen {
namespace {

SpringHair::Kernel available(SpringHair::Kernel asked) {
  return asked != SpringHair::Kernel::kStrands && hasAvx512() ? SpringHair::Kernel::kLanes
                                                              : SpringHair::Kernel::kStrands;
}

// Density targeting: the grids of a spacing, shifted by half a cell along each combination of axes.
constexpr int kDensityShifts = 8;

// The most nodes a density grid may have (gridAround's limit).
constexpr double kMaxDensityNodes = 4e8;

// The most nodes a velocity grid may have: past it the spacing is coarsened (doubled) until it fits.
constexpr double kMaxGridNodes = 2e7;

// A grid of spacing h whose nodes sit on multiples of h, with one empty node beyond the points on every
// side, so every point has all 8 of its cell's corners inside.
template <class T>
void latticeAround(const std::vector<glm::dvec3>& points, const std::vector<double>& inverseMass, double h,
                   GridOf<T>& g) {
  // The free points' bounds, on every core (a minimum and a maximum are the same in any order).
  using Box = std::pair<glm::dvec3, glm::dvec3>;
  const auto [lo, hi] = tbb::parallel_reduce(
      tbb::blocked_range<size_t>(0, points.size(), 16384), Box(glm::dvec3(1e300), glm::dvec3(-1e300)),
      [&](const tbb::blocked_range<size_t>& r, Box box) {
        for (size_t p = r.begin(); p != r.end(); ++p) {
          if (inverseMass[p] == 0.0) continue;
          box.first = glm::min(box.first, points[p]);
          box.second = glm::max(box.second, points[p]);
        }
        return box;
      },
      [](const Box& a, const Box& b) {
        return Box(glm::min(a.first, b.first), glm::max(a.second, b.second));
      });
  g.values.clear();
  if (!(lo.x <= hi.x)) return;
  for (;;) {
    const glm::dvec3 first = glm::floor(lo / h) - 1.0, last = glm::floor(hi / h) + 2.0;
    const glm::dvec3 n = last - first + 1.0;
    if (n.x * n.y * n.z <= kMaxGridNodes) {
      g.origin = first * h;
      g.voxel = h;
      g.size = glm::ivec3(n);
      g.values.assign(size_t(g.size.x) * g.size.y * g.size.z, T(0.0));  // reuses the last frame's memory
      return;
    }
    h *= 2.0;
  }
}

// Out of `shape` to at most `depth` deep: along the ray from the centre for spheres and ellipsoids (the
// direction penetration() measures along), along the nearest face's normal for cuboids.
glm::dvec3 pushedOut(const CollisionShape& s, const glm::dvec3& p, double inside, double depth) {
  const glm::dvec3 v = p - s.centre;
  if (s.kind == ShapeKind::kCuboid) {
    const glm::dvec3 local(glm::dot(v, s.axes[0]), glm::dot(v, s.axes[1]), glm::dot(v, s.axes[2]));
    const glm::dvec3 dent = s.halfExtents - glm::abs(local);
    const int axis = dent.x < dent.y ? (dent.x < dent.z ? 0 : 2) : (dent.y < dent.z ? 1 : 2);
    return p + s.axes[axis] * ((local[axis] < 0.0 ? -1.0 : 1.0) * (inside - depth));
  }
  const double dist = glm::length(v);
  if (!(dist > 0.0)) return p;
  return s.centre + v * ((dist + inside - depth) / dist);
}

}  // namespace

SpringStiffness springStiffness(const Hairstyle& style, const Dynamics& d) {
  const double a = style.hairRadius1, b = style.hairRadius2, e = style.young;
  const double shear = e / (2.0 * (1.0 + style.poisson));
  SpringStiffness k;
  k.stretch = d.stretchStiffnessAuto ? e * M_PI * a * b : d.stretchStiffness;
  k.bend = d.bendStiffnessAuto ? e * M_PI * a * b * b * b / 4.0 : d.bendStiffness;
  k.twist = d.twistStiffnessAuto ? shear * M_PI * a * b * (a * a + b * b) / 4.0 : d.twistStiffness;
  return k;
}

double dynamicsGravity(const Hairstyle& style, const Dynamics& d) {
  return d.gravityAuto ? style.gravity : d.gravity;
}

SpringHair::SpringHair(const Strands& rest, const Hairstyle& style, const Dynamics& dynamics,
                       const Collision& collision, const Strands* densityTarget)
    : rest_(rest),
      damping_(dynamics.damping),
      smoothing_(dynamics.velocitySmoothing),
      smoothingSpacing_(dynamics.smoothingSpacing),
      densityStrength_(densityTarget ? dynamics.densityStrength : 0.0),
      densityRefine_(dynamics.densityRefine) {
  const size_t points = rest.pointCount(), strands = rest.strandCount();
  xRest_.resize(points);
  for (size_t p = 0; p < points; ++p) xRest_[p] = glm::dvec3(rest.points[p]);
  x_ = xRest_;
  restUnit_.assign(points, glm::dvec3(0.0));
  for (size_t st = 0; st < strands; ++st)
    for (uint32_t p = rest.firstPoint[st]; p + 1 < rest.firstPoint[st] + rest.pointsOf(st); ++p)
      restUnit_[p] = glm::normalize(xRest_[p + 1] - xRest_[p]);
  v_.assign(points, glm::dvec3(0.0));
  previousV_.assign(points, glm::dvec3(0.0));
  lastMove_.assign(points, glm::dvec3(0.0));
  mass_.assign(points, 0.0);
  inverseMass_.assign(points, 0.0);
  length_.assign(points, 0.0);
  compliance_.assign(points, 0.0);
  restTension_.assign(points, 0.0);
  bend_.assign(points, 0.0);
  target_.assign(points, glm::dvec3(0.0));
  twistLength_.assign(points, 0.0);
  twistCompliance_.assign(points, -1.0);
  rootDirection_.assign(strands, glm::dvec3(0.0, -1.0, 0.0));
  restTangents_ = tangentsOf(rest);
  const SpringStiffness k = springStiffness(style, dynamics);
  const double lineDensity = style.massDensity * M_PI * style.hairRadius1 * style.hairRadius2;  // kg/m
  const glm::dvec3 load(0.0, -dynamicsGravity(style, dynamics), 0.0);
  for (size_t s = 0; s < strands; ++s) {
    // (The restart state counts a strand's segments from its first point, its root.)
    if (rest.pointsOf(s) == 0) throw InputError("guide " + std::to_string(s) + " has no points");
    const uint32_t p0 = rest.firstPoint[s], n = rest.pointsOf(s) - 1;  // n segments
    if (rest.pointsOf(s) < 2) continue;
    for (uint32_t j = 1; j <= n; ++j) {
      const double l = glm::length(xRest_[p0 + j] - xRest_[p0 + j - 1]);
      if (!(l > 0.0))
        throw InputError("guide " + std::to_string(s) + " has two points at the same place (points " +
                         std::to_string(j - 1) + " and " + std::to_string(j) + "); a segment needs a length");
      length_[p0 + j] = l;
      compliance_[p0 + j] = l / k.stretch;
      mass_[p0 + j - 1] += 0.5 * lineDensity * l;
      mass_[p0 + j] += 0.5 * lineDensity * l;
    }
    for (uint32_t j = 1; j <= n; ++j) inverseMass_[p0 + j] = 1.0 / mass_[p0 + j];
    rootDirection_[s] = (xRest_[p0 + 1] - xRest_[p0]) / length_[p0 + 1];
    auto dir = [&](uint32_t j) { return (xRest_[p0 + j] - xRest_[p0 + j - 1]) / length_[p0 + j]; };
    // Joint j turns segment j + 1 against segment j (the root direction for j = 0): its share of length is
    // the mean of the two, the root's the first segment's (a mirrored ghost segment).
    for (uint32_t j = 0; j < n; ++j) {
      const double share = j == 0 ? length_[p0 + 1] : 0.5 * (length_[p0 + j] + length_[p0 + j + 1]);
      bend_[p0 + j] = k.bend / share;
    }
    // Rest tension, tip to root: the load of everything below segment j along its direction, where
    // that pulls (a hanging segment). A segment the load would compress (hair rising from the scalp)
    // gets none: a column in compression buckles, so its load goes to the bending springs' targets
    // with the rest, and the rest shape is a stable equilibrium, not only an equilibrium.
    glm::dvec3 below(0.0);
    for (uint32_t j = n; j >= 1; --j) {
      below += mass_[p0 + j] * load;
      restTension_[p0 + j] = std::max(glm::dot(below, dir(j)), 0.0);
    }
    // What the tension leaves (per free point: −m g − f_T), carried by the bending springs: solve
    // Bᵀ c = q from the tip (c_j = k_j (b̄_j − b_j), row i of Bᵀ: c_{i−1}/l_i − c_i (1/l_i + 1/l_{i+1}) +
    // c_{i+1}/l_{i+1}), then b̄_j = b_j + c_j / k_j.
    auto tensionForce = [&](uint32_t i) {
      glm::dvec3 f = -restTension_[p0 + i] * dir(i);
      if (i < n) f += restTension_[p0 + i + 1] * dir(i + 1);
      return f;
    };
    std::vector<glm::dvec3> c(n + 2, glm::dvec3(0.0));  // c[j] for joints 0..n−1; c[n], c[n+1] = 0
    for (uint32_t i = n; i >= 1; --i) {
      const glm::dvec3 q = -mass_[p0 + i] * load - tensionForce(i);
      const double li = length_[p0 + i], lnext = i < n ? length_[p0 + i + 1] : 1.0;
      glm::dvec3 rhs = q;
      if (i < n) rhs += c[i] * (1.0 / li + 1.0 / lnext) - c[i + 1] / lnext;
      c[i - 1] = li * rhs;
    }
    for (uint32_t j = 0; j < n; ++j) {
      const glm::dvec3 turn = dir(j + 1) - (j == 0 ? rootDirection_[s] : dir(j));
      target_[p0 + j] = bend_[p0 + j] > 0.0 ? turn + c[j] / bend_[p0 + j] : turn;
    }
    // Twist springs from point i to i + 3 across the middle segment i+1 → i+2: the distance's rate of
    // change with a twist ψ of the far segment about the middle one gives k = G·J / (l ḋ²).
    for (uint32_t i = 0; i + 3 <= n; ++i) {
      const glm::dvec3 a = xRest_[p0 + i], b = xRest_[p0 + i + 1], e = xRest_[p0 + i + 3];
      const glm::dvec3 axis = dir(i + 2), span = e - a;
      const double d = glm::length(span);
      const double rate = glm::dot(span / d, glm::cross(axis, e - b));
      const double l = length_[p0 + i + 2];
      const double stiff = std::min(k.twist / (l * rate * rate), k.stretch / l);
      if (!(rate * rate > 1e-12 * l * l) || !(stiff > 0.0)) continue;
      twistLength_[p0 + i] = d;
      twistCompliance_[p0 + i] = 1.0 / stiff;
    }
  }
  for (const CollisionShape& shape : collision.shapes) {
    if (!(shape.penalty > 0.0)) continue;  // a shape without penalty does not collide, as in grow
    shapes_.push_back(shape);
    const double r = shape.kind == ShapeKind::kSphere ? shape.halfExtents.x
                     : shape.kind == ShapeKind::kEllipsoid
                         ? std::max({shape.halfExtents.x, shape.halfExtents.y, shape.halfExtents.z})
                         : glm::length(shape.halfExtents);
    shapeReach2_.push_back(r * r);
    std::vector<double> depth(points);
    for (size_t p = 0; p < points; ++p) depth[p] = std::max(penetration(shape, xRest_[p]), 0.0);
    restDepth_.push_back(std::move(depth));
  }
  if (densityTarget) {
    // The target's points, each worth hair points / target points so the two densities hold the same
    // total; every level's grid holds both shapes with room to move.
    std::vector<glm::vec3> both = floatPoints();
    both.insert(both.end(), densityTarget->points.begin(), densityTarget->points.end());
    const double scale =
        densityTarget->points.empty() ? 0.0 : double(rest.pointCount()) / double(densityTarget->pointCount());
    const Bounds box = boundsInParallel(both);
    const glm::dvec3 span = glm::dvec3(box.max) - glm::dvec3(box.min);
    for (double h : dynamics.densitySpacings) {
      // gridAround's grid with its padding, and one more node: refused here, naming the key, before
      // gridAround refuses it for the renderer's.
      const glm::dvec3 n = glm::ceil(span / h) + 8.0;
      if (!(n.x * n.y * n.z <= kMaxDensityNodes))
        throw InputError("Dynamics.DensitySpacings " + formatReal(h) + " m makes density grids of " +
                         formatReal(n.x * n.y * n.z) + " nodes over the hair and its target (" +
                         formatReal(span.x) + " x " + formatReal(span.y) + " x " + formatReal(span.z) +
                         " m; " + formatReal(kMaxDensityNodes) + " at most); raise it");
      // Eight copies of the level's grid, shifted by half a cell along every combination of axes: the
      // energy of one grid depends on where its cell walls fall (a surplus of hair may sit one cell
      // away from the place it lacks, or in the same cell), the mean of the eight much less.
      std::vector<Grid> grids;
      double meanSum = 0.0;
      for (int corner = 0; corner < kDensityShifts; ++corner) {
        Grid target = gridAround(both, h, 3);
        target.origin -= 0.5 * h * glm::dvec3(corner & 1, (corner >> 1) & 1, corner >> 2);
        target.size += glm::ivec3(1);
        target.values.assign(size_t(target.size.x) * target.size.y * target.size.z, 0.0f);
        splat(target, densityTarget->points);
        for (float& value : target.values) value = float(double(value) * scale);
        // The target's mean density where it has any: the force's unit at this spacing.
        double sum = 0.0;
        size_t occupied = 0;
        for (float value : target.values)
          if (value > 0.0f) {
            sum += value;
            ++occupied;
          }
        meanSum += occupied ? sum / double(occupied) : 1.0;
        grids.push_back(std::move(target));
      }
      targetMean_.push_back(meanSum / double(grids.size()));
      targets_.push_back(std::move(grids));
    }
    for (size_t level = 0; level < targets_.size(); ++level) startEnergy_.push_back(densityEnergy(level));
  }
  // posedInto writes the points and tangents (xRest_ and restTangents_ keep the rest's), so that handing
  // every other attribute to a frame's guides copies no points.
  rest_.points = {};
  rest_.tangents = {};
}

std::vector<glm::vec3> SpringHair::floatPoints() const {
  std::vector<glm::vec3> out(x_.size());
  for (size_t p = 0; p < x_.size(); ++p) out[p] = glm::vec3(x_[p]);
  return out;
}

std::vector<Grid> SpringHair::densityDifference(size_t level) const {
  std::vector<Grid> out = targets_[level];
  const std::vector<glm::vec3> points = floatPoints();
  for (Grid& d : out) {
    for (float& value : d.values) value = -value;
    splat(d, points);
  }
  return out;
}

double SpringHair::densityEnergy(size_t level) const {
  double sum = 0.0;
  for (const Grid& d : densityDifference(level)) sum += hairgen::densityEnergy(d);
  return sum / double(targets_[level].size());
}

double SpringHair::kineticEnergy() const {
  double sum = 0.0;
  for (size_t p = 0; p < x_.size(); ++p) sum += 0.5 * mass_[p] * glm::dot(v_[p], v_[p]);
  return sum;
}

double SpringHair::maxStretch() const {
  double worst = 0.0;
  for (size_t p = 0; p < x_.size(); ++p)
    if (length_[p] > 0.0)
      worst = std::max(worst, std::abs(glm::length(x_[p] - x_[p - 1]) / length_[p] - 1.0));
  return worst;
}

void SpringHair::factor(double dt) {
  // Per strand, over its free points 1..n: A = M(1 + ⅔cΔt) + (4/9) Δt² K, K = Σ_j k_j B_jᵀ B_j + the
  // rest tension's stiffness, pentadiagonal, where row j of B (joint j) has 1/l_{j+1} at point j + 1,
  // −1/l_{j+1} − 1/l_j at j and 1/l_j at j − 1.
  dt_ = dt;
  const size_t points = x_.size();
  inverseD_.assign(points, 0.0);
  lower1_.assign(points, 0.0);
  lower2_.assign(points, 0.0);
  tbb::parallel_for(size_t(0), rest_.strandCount(), [&](size_t s) {
    const uint32_t p0 = rest_.firstPoint[s], count = rest_.pointsOf(s);
    if (count < 2) return;
    const uint32_t n = count - 1;
    std::vector<double> diag(n + 1, 0.0), off1(n + 1, 0.0), off2(n + 1, 0.0);  // (i,i), (i,i+1), (i,i+2)
    for (uint32_t i = 1; i <= n; ++i) diag[i] = mass_[p0 + i] * (1.0 + kTwoThirds * damping_ * dt);
    // BDF2's (⅔Δt)²: the linear forces at x⁺ = x̂ + ⅔Δt v⁺ over ⅔Δt.
    const double dt2 = (kTwoThirds * dt) * (kTwoThirds * dt);
    // The rest tension's force −T_j e_j / l_j is linear in the points too: stiffness T_j / l_j between
    // the segment's two ends (the root drops out). Implicit, so a long hanging chain's fast string modes
    // (ω up to 2n √(g/L)) stay stable at any substep.
    for (uint32_t j = 1; j <= n; ++j) {
      const double w = dt2 * (restTension_[p0 + j] / length_[p0 + j]);
      diag[j] += w;
      if (j >= 2) {
        diag[j - 1] += w;
        off1[j - 1] -= w;
      }
    }
    for (uint32_t j = 0; j < n; ++j) {
      // Coefficients of joint j on points j − 1, j, j + 1 (point 0 is fixed and drops out).
      const double lNext = length_[p0 + j + 1], lThis = j > 0 ? length_[p0 + j] : 0.0;
      double coef[3] = {j > 0 ? 1.0 / lThis : 0.0, -(1.0 / lNext + (j > 0 ? 1.0 / lThis : 0.0)), 1.0 / lNext};
      if (j == 0) coef[1] = 0.0;  // joint 0: the root point and the root direction are fixed
      const double w = dt2 * bend_[p0 + j];
      for (int a = 0; a < 3; ++a) {
        const int pa = int(j) - 1 + a;
        if (pa < 1) continue;
        for (int b = a; b < 3; ++b) {
          const int pb = int(j) - 1 + b;
          if (pb < 1) continue;
          const double v = w * coef[a] * coef[b];
          if (b == a)
            diag[pa] += v;
          else if (b == a + 1)
            off1[pa] += v;
          else
            off2[pa] += v;
        }
      }
    }
    // L D Lᵀ with bandwidth 2.
    std::vector<double> dd(n + 1, 0.0), l1(n + 1, 0.0), l2(n + 1, 0.0);
    for (uint32_t i = 1; i <= n; ++i) {
      if (i >= 3) l2[i] = off2[i - 2] / dd[i - 2];
      if (i >= 2) l1[i] = (off1[i - 1] - (i >= 3 ? l2[i] * l1[i - 1] * dd[i - 2] : 0.0)) / dd[i - 1];
      dd[i] =
          diag[i] - (i >= 2 ? l1[i] * l1[i] * dd[i - 1] : 0.0) - (i >= 3 ? l2[i] * l2[i] * dd[i - 2] : 0.0);
      inverseD_[p0 + i] = 1.0 / dd[i];
      lower1_[p0 + i] = l1[i];
      lower2_[p0 + i] = l2[i];
    }
  });
  if (available(Kernel::kFastest) == Kernel::kLanes) buildLanePoints();
}

size_t SpringHair::blockLanes(size_t s0, size_t* lanes, uint32_t& n) const {
  const size_t end = std::min(s0 + kLanes, rest_.strandCount());
  size_t count = 0;
  n = 0;
  for (size_t s = s0; s < end; ++s) {
    const uint32_t segments = rest_.pointsOf(s) - 1;
    if (rest_.pointsOf(s) < 2 || segments > kMaxLaneSegments) continue;
    if (n == 0) n = segments;
    if (segments == n) lanes[count++] = s;
  }
  return count;
}

void SpringHair::buildLanePoints() {
  const size_t blocks = (rest_.strandCount() + kLanes - 1) / kLanes;
  laneFirst_.assign(blocks + 1, 0);
  for (size_t b = 0; b < blocks; ++b) {
    size_t lanes[kLanes];
    uint32_t n;
    laneFirst_[b + 1] = laneFirst_[b] + (blockLanes(b * kLanes, lanes, n) ? n + 1 : 0);
  }
  lanePoints_.resize(laneFirst_.back());
  tbb::parallel_for(size_t(0), blocks, [&](size_t b) {
    size_t lanes[kLanes];
    uint32_t n;
    const size_t count = blockLanes(b * kLanes, lanes, n);
    for (size_t l = 0; l < kLanes && count; ++l) {
      const uint32_t p0 = rest_.firstPoint[lanes[l < count ? l : 0]];
      for (uint32_t j = 0; j <= n; ++j) {
        LanePoint& to = lanePoints_[laneFirst_[b] + j];
        const uint32_t p = p0 + j;
        to.mass[l] = mass_[p];
        to.inverseMass[l] = inverseMass_[p];
        to.length[l] = length_[p];
        to.compliance[l] = compliance_[p];
        to.restTension[l] = restTension_[p];
        to.bend[l] = bend_[p];
        to.lower1[l] = lower1_[p];
        to.lower2[l] = lower2_[p];
        to.inverseD[l] = inverseD_[p];
        to.twistLength[l] = twistLength_[p];
        to.twistCompliance[l] = twistCompliance_[p];
        for (int c = 0; c < 3; ++c) to.target[c][l] = target_[p][c];
      }
    }
  });
}

void SpringHair::step(const AccelerationField& field, double dt, bool firstSubstep, bool lastSubstep,
                      Kernel kernel) {
  if (fault_) return;  // the state left its validity: nothing more is computed from it
  if (dt != dt_) factor(dt);
  if (!targets_.empty() && densityStrength_ > 0.0) {
    if (firstSubstep) {
      // The finest level all of whose coarser ones have come down to DensityRefine of their start.
      level_ = 0;
      while (level_ + 1 < targets_.size() && densityEnergy(level_) <= densityRefine_ * startEnergy_[level_])
        ++level_;
    }
    difference_ = densityDifference(level_);
  }
  // Each strand checked as soon as it has stepped, while its points are in cache.
  const size_t strands = rest_.strandCount();
  std::atomic<size_t> first{strands};
  if (available(kernel) == Kernel::kLanes)
    tbb::parallel_for(size_t(0), (strands + kLanes - 1) / kLanes, [&](size_t b) {
      stepBlock(b * kLanes, field, dt);
      checkStrands(b * kLanes, std::min(strands, (b + 1) * kLanes), first);
    });
  else
    tbb::parallel_for(size_t(0), strands, [&](size_t s) {
      stepStrand(s, field, dt);
      checkStrands(s, s + 1, first);
    });
  if (first < strands) {
    fault_ = checkStrand(first);
    return;
  }
  if (lastSubstep && smoothing_ > 0.0) {
    smoothVelocities(smoothing_);
    // Smoothing moves the history too, so the state a frame writes is checked once more.
    fault_ = firstFault();
  }
}

std::optional<SpringHair::Fault> SpringHair::checkStrand(size_t s) const {
  const uint32_t p0 = rest_.firstPoint[s], count = rest_.pointsOf(s);
  // First a quick pass in squares (no root, no division) with bounds 1% inside the true ones: every
  // substep runs it, and a strand it passes is well within them (a NaN fails every comparison).
  constexpr double kLow = (1.0 - 0.99 * kMaxSpringStretch) * (1.0 - 0.99 * kMaxSpringStretch),
                   kHigh = (1.0 + 0.99 * kMaxSpringStretch) * (1.0 + 0.99 * kMaxSpringStretch),
                   kSpeed2 = 0.99 * kMaxSpringSpeed * 0.99 * kMaxSpringSpeed;
  bool within = true;
  for (uint32_t p = p0 + 1; p < p0 + count; ++p) {
    const glm::dvec3 e = x_[p] - x_[p - 1];
    const double length2 = glm::dot(e, e), rest2 = length_[p] * length_[p];
    within &= length2 >= kLow * rest2 && length2 <= kHigh * rest2 && glm::dot(v_[p], v_[p]) <= kSpeed2 &&
              glm::dot(previousV_[p], previousV_[p]) <= kSpeed2 &&
              glm::dot(lastMove_[p], lastMove_[p]) <= kSpeed2;
  }
  if (within) return std::nullopt;
  // restart_state.h's bounds, by the function checkRestartState uses (the rest lengths are the same
  // doubles), so a state that passes here passes there.
  for (uint32_t j = 1; j < count; ++j) {
    const uint32_t p = p0 + j;
    if (const std::optional<SpringSegmentFault> f = springSegmentFault(x_[p - 1], x_[p], v_[p], length_[p]))
      return Fault{*f, s, j};
    // The step's history (the velocity a substep before, the last move) under the velocity's bounds.
    for (const glm::dvec3& earlier : {previousV_[p], lastMove_[p]})
      if (const std::optional<SpringSegmentFault> f = springSpeedFault(earlier)) return Fault{*f, s, j};
  }
  return std::nullopt;
}

std::optional<SpringHair::Fault> SpringHair::firstFault() const {
  const size_t strands = rest_.strandCount();
  std::atomic<size_t> first{strands};
  tbb::parallel_for(tbb::blocked_range<size_t>(0, strands, 256),
                    [&](const tbb::blocked_range<size_t>& r) { checkStrands(r.begin(), r.end(), first); });
  return first < strands ? checkStrand(first) : std::nullopt;
}

void SpringHair::checkStrands(size_t s0, size_t s1, std::atomic<size_t>& first) const {
  for (size_t s = s0; s < s1 && s < first.load(std::memory_order_relaxed); ++s)
    if (checkStrand(s)) return atomicMin(first, s);
}

void SpringHair::projectStretch(size_t s, double dt, int iterations, std::vector<double>& lambda) {
  // XPBD on all of the strand's segment constraints C_j = |e_j| − l_j at once: each iteration solves the
  // tridiagonal (J W Jᵀ + α/Δt²) Δλ = −C − (α/Δt²) λ and moves the points by W Jᵀ Δλ.
  const uint32_t p0 = rest_.firstPoint[s], n = rest_.pointsOf(s) - 1;
  std::vector<glm::dvec3>& x = x_;
  thread_local std::vector<glm::dvec3> u;
  thread_local std::vector<double> diag, upper, rhs, inverseDiag, alpha, base, inverseLength;
  u.resize(n + 2);
  for (auto* v : {&diag, &upper, &rhs, &inverseDiag, &alpha, &base, &inverseLength}) v->resize(n + 2);
  const double dt2 = dt * dt;
  // What every pass has the same: α/Δt², the diagonal before elimination, 1/l.
  for (uint32_t j = 1; j <= n; ++j) {
    alpha[j] = compliance_[p0 + j] / dt2;
    base[j] = inverseMass_[p0 + j - 1] + inverseMass_[p0 + j] + alpha[j];
    inverseLength[j] = 1.0 / length_[p0 + j];
  }
  // `iterations` passes, and more (up to kMaxPasses) while a segment is still off its length by more
  // than kStretchTolerance: a big push (a collision, a strong density force) needs a few Newton steps.
  constexpr int kMaxPasses = 32;
  constexpr double kStretchTolerance = 1e-3;
  for (int it = 0; it < kMaxPasses; ++it) {
    double worst = 0.0;
    for (uint32_t j = 1; j <= n; ++j) {
      const glm::dvec3 e = x[p0 + j] - x[p0 + j - 1];
      const double len = glm::length(e);
      worst = std::max(worst, std::abs(len - length_[p0 + j]) * inverseLength[j]);
      u[j] = (1.0 / len) * e;
      diag[j] = base[j];
      rhs[j] = -(len - length_[p0 + j]) - alpha[j] * lambda[j];
    }
    if (it >= iterations && worst <= kStretchTolerance) break;
    for (uint32_t j = 1; j < n; ++j) upper[j] = -inverseMass_[p0 + j] * glm::dot(u[j], u[j + 1]);
    solveTridiagonal(upper.data(), diag.data(), rhs.data(), inverseDiag.data(), n);
    for (uint32_t j = 1; j <= n; ++j) {
      lambda[j] += rhs[j];
      const double next = j < n ? rhs[j + 1] : 0.0;
      x[p0 + j] += inverseMass_[p0 + j] * (rhs[j] * u[j] - (j < n ? next * u[j + 1] : glm::dvec3(0.0)));
    }
  }
}

void SpringHair::predict(size_t s, const AccelerationField& field, double dt, glm::dvec3* before) {
  const uint32_t p0 = rest_.firstPoint[s], n = rest_.pointsOf(s) - 1;
  thread_local std::vector<glm::dvec3> turn, force;
  turn.resize(n + 2);
  force.resize(n + 1);
  // Bending: g_j = k_j (b̄_j − b_j), and each point's force Σ_j (B_j)_i g_j.
  // Each segment's direction over its rest length (e_j / l_j), once.
  thread_local std::vector<glm::dvec3> unit;
  thread_local std::vector<double> inverseLength;
  unit.resize(n + 2);
  inverseLength.resize(n + 2);
  // The linear forces (bending, rest tension) at x̂ = x + (Δt/3) w, where BDF2 takes them with
  // −(2/3) Δt K v⁺ on the left.
  unit[0] = rootDirection_[s];
  inverseLength[n + 1] = 0.0;
  const double third = dt / 3.0;
  for (uint32_t j = 1; j <= n; ++j) {
    inverseLength[j] = 1.0 / length_[p0 + j];
    const glm::dvec3 e = (x_[p0 + j] - x_[p0 + j - 1]) +
                         third * (lastMove_[p0 + j] - (j > 1 ? lastMove_[p0 + j - 1] : glm::dvec3(0.0)));
    unit[j] = e * inverseLength[j];
  }
  unit[n + 1] = glm::dvec3(0.0);
  for (uint32_t j = 0; j < n; ++j) turn[j] = bend_[p0 + j] * (target_[p0 + j] - (unit[j + 1] - unit[j]));
  turn[n] = turn[n + 1] = glm::dvec3(0.0);  // no joint at the tip
  const double twoThirdsDt = kTwoThirds * dt;
  for (uint32_t i = 1; i <= n; ++i) {
    const uint32_t p = p0 + i;
    // Row i of Bᵀ: joints i − 1, i and i + 1 (turn[n] is 0, and 1/l_{n+1} is 0).
    glm::dvec3 f = turn[i - 1] * inverseLength[i] + turn[i + 1] * inverseLength[i + 1] -
                   turn[i] * (inverseLength[i] + inverseLength[i + 1]);
    // The rest tension along the segments, turning with them.
    f -= restTension_[p] * unit[i];
    if (i < n) f += restTension_[p + 1] * unit[i + 1];
    f += mass_[p] * field.at(x_[p], v_[p]);
    if (!difference_.empty() && densityStrength_ > 0.0) {
      // The memo's F in units of the target's mean density, at most 1 long: where the shapes are far
      // apart the push is DensityStrength toward the target, not a kick that flings the hair.
      // The mean of the eight shifted grids' forces.
      glm::dvec3 push(0.0);
      for (const Grid& d : difference_) push += densityForce(d, x_[p]);
      push /= double(difference_.size()) * targetMean_[level_];
      const double size = glm::length(push);
      if (size > 1.0) push /= size;
      f += mass_[p] * densityStrength_ * push;
    }
    force[i] = mass_[p] * (kFourThirds * v_[p] - kOneThird * previousV_[p]) + twoThirdsDt * f;
  }
  // A v⁺ = M (4/3 v − 1/3 v⁻) + (2/3) Δt f(x̂), A = M (1 + ⅔cΔt) + (4/9) Δt² K = L D Lᵀ (the damping −c M v⁺
  // and the linear forces at x⁺ implicit).
  for (uint32_t i = 1; i <= n; ++i) {
    const uint32_t p = p0 + i;
    if (i >= 2) force[i] -= lower1_[p] * force[i - 1];
    if (i >= 3) force[i] -= lower2_[p] * force[i - 2];
  }
  for (uint32_t i = 1; i <= n; ++i) force[i] *= inverseD_[p0 + i];
  for (uint32_t i = n; i >= 1; --i) {
    if (i + 1 <= n) force[i] -= lower1_[p0 + i + 1] * force[i + 1];
    if (i + 2 <= n) force[i] -= lower2_[p0 + i + 2] * force[i + 2];
  }
  for (uint32_t i = 1; i <= n; ++i) {
    before[i] = x_[p0 + i];
    x_[p0 + i] += third * lastMove_[p0 + i] + twoThirdsDt * force[i];
  }
}

bool SpringHair::constrain(size_t s, double dt) {
  const uint32_t p0 = rest_.firstPoint[s], n = rest_.pointsOf(s) - 1;
  bool twisted = false;
  for (uint32_t i = 0; i + 3 <= n; ++i) {
    const uint32_t a = p0 + i, b = p0 + i + 3;
    if (twistCompliance_[a] < 0.0) continue;
    twisted = true;
    const glm::dvec3 e = x_[b] - x_[a];
    const double len = glm::length(e);
    const double wsum = inverseMass_[a] + inverseMass_[b] + twistCompliance_[a] / (dt * dt);
    const double dl = -(len - twistLength_[a]) / wsum;
    if (inverseMass_[a] > 0.0) x_[a] -= inverseMass_[a] * dl * e / len;  // a root stays where it is
    x_[b] += inverseMass_[b] * dl * e / len;
  }
  bool moved = twisted;
  for (size_t c = 0; c < shapes_.size(); ++c)
    for (uint32_t i = 1; i <= n; ++i) {
      const glm::dvec3 v = x_[p0 + i] - shapes_[c].centre;
      if (glm::dot(v, v) < shapeReach2_[c]) moved = collide(c, p0 + i, x_[p0 + i]) || moved;
    }
  return moved;
}

bool SpringHair::collide(size_t c, uint32_t p, glm::dvec3& x) const {
  const double inside = penetration(shapes_[c], x), allowed = restDepth_[c][p];
  if (!(inside > allowed + 1e-9)) return false;
  x = pushedOut(shapes_[c], x, inside, allowed);
  return true;
}

void SpringHair::finish(size_t s, double dt, const glm::dvec3* before) {
  const uint32_t p0 = rest_.firstPoint[s], n = rest_.pointsOf(s) - 1;
  // v⁺ = (3x⁺ − 4x + x⁻)/(2Δt) = 3/2 w⁺ − 1/2 w, from the projected points.
  for (uint32_t i = 1; i <= n; ++i) {
    const uint32_t p = p0 + i;
    const glm::dvec3 move = (x_[p] - before[i]) / dt;
    previousV_[p] = v_[p];
    v_[p] = kThreeHalves * move - 0.5 * lastMove_[p];
    lastMove_[p] = move;
  }
}

void SpringHair::stepStrand(size_t s, const AccelerationField& field, double dt) {
  if (rest_.pointsOf(s) < 2) return;
  thread_local std::vector<glm::dvec3> before;
  thread_local std::vector<double> lambda;
  const uint32_t n = rest_.pointsOf(s) - 1;
  before.resize(n + 1);
  predict(s, field, dt, before.data());
  // Inextensible (to the stretch compliance), then the twist springs and collisions, and where they
  // moved a point the stretch once more.
  lambda.assign(n + 2, 0.0);
  projectStretch(s, dt, 1, lambda);
  if (constrain(s, dt)) {
    lambda.assign(n + 2, 0.0);
    projectStretch(s, dt, 1, lambda);
  }
  finish(s, dt, before.data());
}

void SpringHair::stepBlock(size_t s0, const AccelerationField& field, double dt) {
  // stepStrand for the block's lanes together, in vectors; any other strand on its own.
  size_t lanes[kLanes];
  uint32_t n;
  const size_t count = blockLanes(s0, lanes, n);
  for (size_t s = s0, l = 0; s < std::min(s0 + kLanes, rest_.strandCount()); ++s) {
    if (l < count && lanes[l] == s)
      ++l;
    else if (rest_.pointsOf(s) >= 2)
      stepStrand(s, field, dt);
  }
  if (count == 0) return;
  const size_t block = s0 / kLanes;
  bool again[kLanes] = {};
  std::fill(again, again + count, true);
  if (difference_.empty() || !(densityStrength_ > 0.0)) {
    stepLanes(block, lanes, count, n, field, dt);
    return;
  }
  // With density targeting: its forces strand by strand.
  thread_local std::vector<glm::dvec3> before;
  before.resize(kLanes * (n + 1));
  for (size_t l = 0; l < count; ++l) predict(lanes[l], field, dt, &before[l * (n + 1)]);
  projectStretchLanes(block, lanes, count, n, dt, again);
  bool any = false;
  for (size_t l = 0; l < count; ++l) any = (again[l] = constrain(lanes[l], dt)) || any;
  if (any) projectStretchLanes(block, lanes, count, n, dt, again);
  for (size_t l = 0; l < count; ++l) finish(lanes[l], dt, &before[l * (n + 1)]);
}

void SpringHair::smoothVelocities(double fraction) {
  if (!(fraction > 0.0)) return;
  // Masses and momenta (m, m v) of the free points on the grid (W M), filtered (S), the node velocity
  // their quotient (D⁻¹), filtered again (S) and read back with the same tent weights (Wᵀ).
  GridOf<glm::dvec4>& grid = velocityGrid_;
  latticeAround(x_, inverseMass_, smoothingSpacing_, grid);
  if (grid.values.empty()) return;
  std::vector<glm::dvec3>& where = smoothWhere_;
  std::vector<glm::dvec4>& what = smoothWhat_;
  std::vector<size_t>& which = smoothWhich_;
  if (which.empty())  // the free points, which never change
    for (size_t p = 0; p < x_.size(); ++p)
      if (inverseMass_[p] != 0.0) which.push_back(p);
  where.resize(which.size());
  what.resize(which.size());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, which.size(), 16384),
                    [&](const tbb::blocked_range<size_t>& r) {
                      for (size_t k = r.begin(); k != r.end(); ++k) {
                        const size_t p = which[k];
                        where[k] = x_[p];
                        what[k] = glm::dvec4(mass_[p] * v_[p], mass_[p]);
                      }
                    });
  splatValues(grid, where, what, smoothSorted_);
  smoothInPlace(grid);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, grid.values.size(), 16384),
                    [&](const tbb::blocked_range<size_t>& r) {
                      for (size_t i = r.begin(); i != r.end(); ++i) {
                        glm::dvec4& node = grid.values[i];
                        node = node.w > 0.0 ? glm::dvec4(glm::dvec3(node) / node.w, 1.0) : glm::dvec4(0.0);
                      }
                    });
  smoothInPlace(grid);
  tbb::parallel_for(size_t(0), which.size(), [&](size_t k) {
    const size_t p = which[k];
    const glm::dvec3 target(grid.sample(where[k]));
    // BDF2's history takes the same change, as if the hair had always moved with it: the extrapolations
    // of the next step (4/3 v − 1/3 v⁻, x + (Δt/3) w) then see exactly the smoothed velocity.
    const glm::dvec3 change = fraction * (target - v_[p]);
    v_[p] += change;
    previousV_[p] += change;
    lastMove_[p] += change;
  });
}

void SpringHair::setMotion(const std::vector<glm::dvec3>& v) {
  v_ = v;
  previousV_ = v;
  lastMove_ = v;
}

Strands SpringHair::posed(const Pose& pose) const {
  Strands out;
  posedInto(pose, out);
  return out;
}

void SpringHair::posedInto(const Pose& pose, Strands& out, Kernel kernel) const {
  out.assignRestKeepingBuffers(rest_);  // every attribute but the points and tangents is the rest's
  const bool still = pose.isIdentity(), lanes = available(kernel) == Kernel::kLanes;
  tbb::parallel_for(size_t(0), rest_.strandCount(), [&](size_t s) {
    const uint32_t p0 = rest_.firstPoint[s], count = rest_.pointsOf(s);
    uint32_t j = 0;
    if (lanes && count > kLanes) {  // eight at a time while each point starts a segment (the last
                                    // eight overlapping the ones before)
      for (; j + kLanes < count; j += kLanes) poseEightLanes(s, j, pose, out);
      if (j + 1 < count) poseEightLanes(s, count - 1 - kLanes, pose, out);
      j = count - 1;
    }
    glm::dvec3 restDir(0.0), dir(0.0);
    if (j > 0) {
      restDir = restUnit_[p0 + j - 1];
      dir = glm::normalize(x_[p0 + j] - x_[p0 + j - 1]);
    }
    for (; j < count; ++j) {
      const uint32_t p = p0 + j;
      // The input point plus the motion: at rest exactly the input.
      // (xRest_ holds the input points exactly, in doubles.)
      out.points[p] = glm::vec3(pose.apply(xRest_[p] + (x_[p] - xRest_[p])));
      glm::dvec3 t(restTangents_[p]);
      if (count >= 2) {
        // Turned with its segment (the one it starts, or the last): the minimal rotation.
        if (j + 1 < count) {
          restDir = restUnit_[p];
          dir = glm::normalize(x_[p + 1] - x_[p]);
        }
        t = transportFast(restDir, dir, t);
      }
      out.tangents[p] = glm::vec3(still ? t : pose.rotation * t);  // a rotation keeps it unit
    }
  });
}

std::vector<double> SpringHair::state() const {
  std::vector<double> out;
  stateInto(out);
  return out;
}

void SpringHair::stateInto(std::vector<double>& out) const {
  // Per segment, its end point: the roots are the head's and never move.
  // (Each strand's first point is its root, so strand s's points after it are segments
  // firstPoint[s] − s onward.)
  out.resize((x_.size() - rest_.strandCount()) * kStateValues);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, rest_.strandCount(), 1024),
                    [&](const tbb::blocked_range<size_t>& r) {
                      for (size_t s = r.begin(); s != r.end(); ++s) {
                        const uint32_t p0 = rest_.firstPoint[s], count = rest_.pointsOf(s);
                        double* v = &out[kStateValues * (p0 - s)];
                        for (uint32_t p = p0 + 1; p < p0 + count; ++p, v += kStateValues)
                          for (int c = 0; c < 3; ++c) {
                            v[c] = x_[p][c];
                            v[3 + c] = v_[p][c];
                            v[6 + c] = previousV_[p][c];
                            v[9 + c] = lastMove_[p][c];
                          }
                      }
                    });
}

void SpringHair::restore(const std::vector<double>& state, const std::string& source) {
  requireSpringStateSize(x_.size() - rest_.strandCount(), state.size(), source);
  size_t k = 0;
  for (size_t p = 0; p < x_.size(); ++p) {
    if (length_[p] == 0.0) {
      x_[p] = xRest_[p];
      v_[p] = previousV_[p] = lastMove_[p] = glm::dvec3(0.0);
      continue;
    }
    const double* v = &state[kStateValues * k++];
    x_[p] = glm::dvec3(v[0], v[1], v[2]);
    v_[p] = glm::dvec3(v[3], v[4], v[5]);
    previousV_[p] = glm::dvec3(v[6], v[7], v[8]);
    lastMove_[p] = glm::dvec3(v[9], v[10], v[11]);
  }
  // The bounds every step keeps (and checkRestartState checks, with the rest guides' points).
  fault_.reset();
  if (const std::optional<Fault> f = firstFault()) {
    x_ = xRest_;
    v_.assign(v_.size(), glm::dvec3(0.0));
    previousV_.assign(v_.size(), glm::dvec3(0.0));
    lastMove_.assign(v_.size(), glm::dvec3(0.0));
    throw InputError({source, 0}, "its simulation state's strand " + std::to_string(f->strand) + ", point " +
                                      std::to_string(f->point) +
                                      " is not a state a simulation writes (not finite, stretched past " +
                                      "its bound, or too fast); simulate from the first frame");
  }
}

}  // namespace hairgen
