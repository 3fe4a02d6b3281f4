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

namespace hairgen {

// A material frame on the rod: where it is, and its three unit axes.
struct RodFrame {
  glm::dvec3 position{0.0};
  glm::dvec3 n0{0.0, 1.0, 0.0};  // tangent
  glm::dvec3 n1{0.0, 0.0, 1.0};
  glm::dvec3 n2{1.0, 0.0, 0.0};
};

// The follicle frame of thesis §4.1.4.1 with "up" = +y: n1 = n0 × up normalised (+z when n0 ∥ up),
// n2 = n0 × n1. `normal` must be non-zero.
RodFrame follicleFrame(const glm::dvec3& root, const glm::dvec3& normal);

// The frame reached after arc length u along an element whose start frame is `start` and whose
// Darboux vector (world coordinates) is `darboux`.
RodFrame advance(const RodFrame& start, const glm::dvec3& darboux, double u);

// Darboux vector of an element from its start frame and (τ, κ1, κ2).
inline glm::dvec3 darbouxVector(const RodFrame& f, double tau, double kappa1, double kappa2) {
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
struct HelixCoefficients {
  double a, b, c;
};
inline HelixCoefficients helixCoefficients(double omega, double invOmega, double u, double cosX,
                                           double sinX) {
  const double x = omega * u;
  if (std::abs(x) < kHelixSeriesBelow) {
    const double x2 = x * x;
    return {u * (1.0 - x2 / 6.0 * (1.0 - x2 / 20.0 * (1.0 - x2 / 42.0))),
            u * u * (0.5 - x2 / 24.0 * (1.0 - x2 / 30.0 * (1.0 - x2 / 56.0))),
            u * u * u * (1.0 / 6.0 - x2 / 120.0 * (1.0 - x2 / 42.0 * (1.0 - x2 / 72.0)))};
  }
  const double inv2 = invOmega * invOmega;
  return {sinX * invOmega, (1.0 - cosX) * inv2, (x - sinX) * inv2 * invOmega};
}

// One element of the rod: its start frame, constant Darboux vector W, and the closed forms over
// u ∈ [0, ℓ]. Building one costs one sin/cos pair (for its end frame); everything else is algebra.
class HelixElement {
 public:
  HelixElement(const RodFrame& start, const glm::dvec3& darboux, double length);

  const RodFrame& start() const { return start_; }
  const RodFrame& end() const { return end_; }
  double length() const { return length_; }
  // |W|, and cos and sin of |W| ℓ (1 and 0 below kHelixSeriesBelow, where the closed forms are not used).
  double omega() const { return omega_; }
  double cosLength() const { return cosL_; }
  double sinLength() const { return sinL_; }
  glm::dvec3 position(double u) const;
  RodFrame frame(double u) const;
  // ∫0^ℓ (r(u) − r(0)) du, metres².
  glm::dvec3 displacementIntegral() const;

  // Calls visit(j, u_j, cos Ωu_j, sin Ωu_j) for u_j = first + j·step, j < count, with two sin/cos
  // pairs in all: the angles advance by a rotation recurrence instead of a library call per point.
  // at(u, cos, sin) is the position there.
  template <class Visit>
  void visitGrid(double first, double step, size_t count, Visit&& visit) const;
  glm::dvec3 at(double u, double cosX, double sinX) const {
    return along(u, helixCoefficients(omega_, invOmega_, u, cosX, sinX));
  }

 private:
  // The centreline at u from its coefficients there (the file comment of super_helix.cpp).
  glm::dvec3 along(double u, const HelixCoefficients& k) const {
    return start_.position + u * start_.n0 + k.b * wn0_ + k.c * wwn0_;
  }

  RodFrame start_, end_;
  glm::dvec3 w_, wn0_, wwn0_;  // W, W×n0, W×(W×n0)
  double omega_, invOmega_;    // invOmega_ is 0 for a straight element
  double length_;
  double sinL_, cosL_;  // of Ω ℓ
};

// Walks the elements of a rod from its root: visit(element, arc length at its start, index).
template <class Visit>
void forEachElement(const RodFrame& root, std::span<const double> lengths, std::span<const double> q,
                    Visit&& visit) {
  RodFrame start = root;
  double s = 0.0;
  for (size_t e = 0; e < lengths.size(); ++e) {
    HelixElement element(start, darbouxVector(start, q[3 * e], q[3 * e + 1], q[3 * e + 2]), lengths[e]);
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

template <class Visit>
void HelixElement::visitGrid(double first, double step, size_t count, Visit&& visit) const {
  if (count == 0) return;
  const double dx = omega_ * step;
  const double cd = std::cos(dx), sd = std::sin(dx);
  double c = cd, s = sd;
  if (first != step) {  // the grid usually starts one step into the element
    c = std::cos(omega_ * first);
    s = std::sin(omega_ * first);
  }
  for (size_t j = 0; j < count; ++j) {
    visit(j, first + static_cast<double>(j) * step, c, s);
    const double next = c * cd - s * sd;
    s = s * cd + c * sd;
    c = next;
  }
}

}  // namespace hairgen
