// Static Super-Helix (Bertails et al. 2006, as used by Lansink 2010 §4.1.1): a rod of N helical
// elements, each with constant twist τ and curvatures κ1, κ2, chained C1 from a clamped root.
//
// Generalised coordinates q = (τ_1, κ1_1, κ2_1, τ_2, ...), 3 per element, in 1/m. The material frame
// is (n0 = tangent, n1, n2); within element Q it rotates about the constant Darboux vector
// Ω = τ n0(0) + κ1 n1(0) + κ2 n2(0) at rate |Ω| per metre. Every closed form below switches to its
// Taylor series when |Ω|·u is small, so a straight element is exact and the energy is smooth in q.
#pragma once

#include <cmath>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "libcore/config/params.h"
#include "libcore/physics/dual.h"

namespace hairgen {

// The dual number the energy's gradient is taken in: 8 coordinates' derivatives per evaluation.
inline constexpr int kGradientWidth = 8;
using EnergyGradient = Dual<kGradientWidth>;

// Everything from here to forEachElement is written for a scalar T: double, or a Dual (dual.h) when
// the quasi-Newton minimiser wants derivatives of the same closed forms.
template <class T>
struct BasicRodFrame {
  Vec3<T> position{T(0.0)};
  Vec3<T> n0{T(0.0), T(1.0), T(0.0)};  // tangent
  Vec3<T> n1{T(0.0), T(0.0), T(1.0)};
  Vec3<T> n2{T(1.0), T(0.0), T(0.0)};

  BasicRodFrame() = default;
  template <class U>
  explicit BasicRodFrame(const BasicRodFrame<U>& f) : position(f.position), n0(f.n0), n1(f.n1), n2(f.n2) {}
};
using RodFrame = BasicRodFrame<double>;

// The follicle frame of thesis §4.1.4.1 with "up" = +y: n1 = n0 × up normalised (+z when n0 ∥ up),
// n2 = n0 × n1. `normal` must be non-zero.
RodFrame follicleFrame(const glm::dvec3& root, const glm::dvec3& normal);

// The frame reached after arc length u along an element whose start frame is `start` and whose
// Darboux vector (world coordinates) is `darboux`.
RodFrame advance(const RodFrame& start, const glm::dvec3& darboux, double u);

// Darboux vector of an element from its start frame and (τ, κ1, κ2).
template <class T>
Vec3<T> darbouxVector(const BasicRodFrame<T>& f, const T& tau, const T& kappa1, const T& kappa2) {
  return tau * f.n0 + kappa1 * f.n1 + kappa2 * f.n2;
}

// Rest twist and curvatures of a helix of radius r and rise per turn `step` (thesis Table 2 values):
// with c = step/2π, κ⁰ = r/(r² + c²), τ⁰ = c/(r² + c²) — exact for a helix. The thesis' 1/r and
// step/(2π r²) are their approximations for c ≪ r. r = 0 gives a straight rest shape (τ⁰ = 0).
struct RestShape {
  double tau = 0.0, kappa1 = 0.0, kappa2 = 0.0;  // 1/m
};
RestShape restShape(double helixRadius, double helixStep);

// Below this |Ω u| the closed forms switch to their Taylor series (truncation error < 1e-17).
inline constexpr double kHelixSeriesBelow = 0.05;

// a = sin x/Ω, b = (1 − cos x)/Ω², c = (x − sin x)/Ω³ at u (x = Ω u), given cos x, sin x and 1/Ω;
// Taylor series below kHelixSeriesBelow, where cos x, sin x and 1/Ω are not read.
template <class T>
struct BasicHelixCoefficients {
  T a, b, c;
};
using HelixCoefficients = BasicHelixCoefficients<double>;
template <class T>
BasicHelixCoefficients<T> helixCoefficients(const T& omega, const T& invOmega, double u, const T& cosX,
                                            const T& sinX) {
  const T x = omega * u;
  if (std::abs(valueOf(x)) < kHelixSeriesBelow) {
    const T x2 = x * x;
    return {u * (1.0 - x2 / 6.0 * (1.0 - x2 / 20.0 * (1.0 - x2 / 42.0))),
            u * u * (0.5 - x2 / 24.0 * (1.0 - x2 / 30.0 * (1.0 - x2 / 56.0))),
            u * u * u * (1.0 / 6.0 - x2 / 120.0 * (1.0 - x2 / 42.0 * (1.0 - x2 / 72.0)))};
  }
  const T inv2 = invOmega * invOmega;
  return {sinX * invOmega, (1.0 - cosX) * inv2, (x - sinX) * inv2 * invOmega};
}

// One element of the rod: its start frame, constant Darboux vector W, and the closed forms over
// u ∈ [0, ℓ]. Building one costs one sin/cos pair (for its end frame); everything else is algebra.
template <class T>
class BasicHelixElement {
 public:
  BasicHelixElement(const BasicRodFrame<T>& start, const Vec3<T>& darboux, double length);

  const BasicRodFrame<T>& start() const { return start_; }
  const BasicRodFrame<T>& end() const { return end_; }
  double length() const { return length_; }
  Vec3<T> position(double u) const;
  BasicRodFrame<T> frame(double u) const;
  // ∫0^ℓ (r(u) − r(0)) du, metres².
  Vec3<T> displacementIntegral() const;

  // Calls visit(j, u_j, cos Ωu_j, sin Ωu_j) for u_j = first + j·step, j < count, with two sin/cos
  // pairs in all: the angles advance by a rotation recurrence instead of a library call per point.
  // at(u, cos, sin) is the position there.
  template <class Visit>
  void visitGrid(double first, double step, size_t count, Visit&& visit) const;
  Vec3<T> at(double u, const T& cosX, const T& sinX) const;
  // The values alone (no derivatives) of at() and position().
  glm::dvec3 valueAt(double u, double cosX, double sinX) const;
  glm::dvec3 valuePosition(double u) const;

 private:
  // The centreline at u from its coefficients there (the file comment of super_helix.cpp), with
  // derivatives and as values alone.
  Vec3<T> along(double u, const BasicHelixCoefficients<T>& k) const {
    return start_.position + u * start_.n0 + k.b * wn0_ + k.c * wwn0_;
  }
  glm::dvec3 valueAlong(double u, const HelixCoefficients& k) const {
    return valueOf(start_.position) + u * valueOf(start_.n0) + k.b * valueOf(wn0_) + k.c * valueOf(wwn0_);
  }

  BasicRodFrame<T> start_, end_;
  Vec3<T> w_, wn0_, wwn0_;  // W, W×n0, W×(W×n0)
  T omega_, invOmega_;      // invOmega_ is 0 for a straight element
  double length_;
  T sinL_, cosL_;  // of Ω ℓ
};
using HelixElement = BasicHelixElement<double>;

// Walks the elements of a rod from its root: visit(element, arc length at its start, index).
template <class T, class Visit>
void forEachElement(const BasicRodFrame<T>& root, std::span<const double> lengths, std::span<const T> q,
                    Visit&& visit) {
  BasicRodFrame<T> start = root;
  double s = 0.0;
  for (size_t e = 0; e < lengths.size(); ++e) {
    BasicHelixElement<T> element(start, darbouxVector(start, q[3 * e], q[3 * e + 1], q[3 * e + 2]),
                                 lengths[e]);
    visit(element, s, e);
    start = element.end();
    s += lengths[e];
  }
}

// Positions and unit tangents at arc lengths `s` (ascending, within [0, L]).
void sampleRod(const RodFrame& root, std::span<const double> lengths, std::span<const double> q,
               std::span<const double> s, std::vector<glm::dvec3>& positions,
               std::vector<glm::dvec3>* tangents);

// Output arc lengths: every `step` from 0, the last exactly at `total`.
std::vector<double> sampleArcLengths(double total, double step, bool includeRoot);

template <class T>
Vec3<T> BasicHelixElement<T>::at(double u, const T& cosX, const T& sinX) const {
  return along(u, helixCoefficients(omega_, invOmega_, u, cosX, sinX));
}

template <class T>
glm::dvec3 BasicHelixElement<T>::valueAt(double u, double cosX, double sinX) const {
  return valueAlong(u, helixCoefficients(valueOf(omega_), valueOf(invOmega_), u, cosX, sinX));
}

template <class T>
template <class Visit>
void BasicHelixElement<T>::visitGrid(double first, double step, size_t count, Visit&& visit) const {
  using std::cos, std::sin;
  if (count == 0) return;
  const T dx = omega_ * step;
  const T cd = cos(dx), sd = sin(dx);
  T c = cd, s = sd;
  if (first != step) {  // the grid usually starts one step into the element
    c = cos(omega_ * first);
    s = sin(omega_ * first);
  }
  for (size_t j = 0; j < count; ++j) {
    visit(j, first + static_cast<double>(j) * step, c, s);
    T next = c * cd - s * sd;
    s = s * cd + c * sd;
    c = next;
  }
}

}  // namespace hairgen
