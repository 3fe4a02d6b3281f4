// Static Super-Helix (Bertails et al. 2006, as used by Lansink 2010 §4.1.1): a rod of N helical
// elements, each with constant twist τ and curvatures κ1, κ2, chained C1 from a clamped root.
//
// Generalised coordinates q = (τ_1, κ1_1, κ2_1, τ_2, ...), 3 per element, in 1/m. The material frame
// is (n0 = tangent, n1, n2); within element Q it rotates about the constant Darboux vector
// Ω = τ n0(0) + κ1 n1(0) + κ2 n2(0) at rate |Ω| per metre. Every closed form below switches to its
// Taylor series when |Ω|·u is small, so a straight element is exact and the energy is smooth in q.
#pragma once

#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "libcore/params.h"

namespace hairgen {

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

// Positions and unit tangents at arc lengths `s` (ascending, within [0, L]).
void sampleRod(const RodFrame& root, std::span<const double> lengths, std::span<const double> q,
               std::span<const double> s, std::vector<glm::dvec3>& positions, std::vector<glm::dvec3>* tangents);

// ∫ (r(s) − r(0))·ŷ ds over the whole rod in closed form (thesis §4.1.1.3.2), metres².
double heightIntegral(const RodFrame& root, std::span<const double> lengths, std::span<const double> q);

// Output arc lengths: every `step` from 0, the last exactly at `total`.
std::vector<double> sampleArcLengths(double total, double step, bool includeRoot);

}  // namespace hairgen
