// Super-Helix reconstruction, Lansink 2010 §4.1.1.2 (after Bertails et al. 2006).
//
// With W the Darboux vector, Ω = |W| and x = Ω·u, a vector v carried by the frame is
//   R(u)v = v + a(u)(W×v) + b(u)(W×(W×v)),    a = sin x / Ω,   b = (1 − cos x)/Ω²,
// and the centreline, the integral of the tangent, is
//   r(u) = r(0) + u n0 + b(u)(W×n0) + c(u)(W×(W×n0)),    c = (x − sin x)/Ω³.
// Written this way no coefficient divides by Ω once its series is used for small x.
#include "libcore/super_helix.h"

#include <cmath>

namespace hairgen {
namespace {

constexpr double kSeriesBelow = 0.05;  // |Ω u| below which the Taylor series is used (error < 1e-17)

struct Coefficients {
  double a, b, c;
};

Coefficients coefficients(double omega, double u) {
  double x = omega * u;
  if (std::abs(x) < kSeriesBelow) {
    double x2 = x * x;
    return {u * (1.0 - x2 / 6.0 * (1.0 - x2 / 20.0 * (1.0 - x2 / 42.0))),
            u * u * (0.5 - x2 / 24.0 * (1.0 - x2 / 30.0 * (1.0 - x2 / 56.0))),
            u * u * u * (1.0 / 6.0 - x2 / 120.0 * (1.0 - x2 / 42.0 * (1.0 - x2 / 72.0)))};
  }
  double s = std::sin(x), c = std::cos(x);
  return {s / omega, (1.0 - c) / (omega * omega), (x - s) / (omega * omega * omega)};
}

glm::dvec3 rotate(const glm::dvec3& v, const glm::dvec3& w, const Coefficients& k) {
  glm::dvec3 wv = glm::cross(w, v);
  return v + k.a * wv + k.b * glm::cross(w, wv);
}

}  // namespace

RodFrame follicleFrame(const glm::dvec3& root, const glm::dvec3& normal) {
  RodFrame f;
  f.position = root;
  f.n0 = glm::normalize(normal);
  const glm::dvec3 up(0.0, 1.0, 0.0);  // the thesis calls this "down"; +y is up (DESIGN §7)
  glm::dvec3 side = glm::cross(f.n0, up);
  f.n1 = glm::length(side) > 1e-9 ? glm::normalize(side) : glm::dvec3(0.0, 0.0, 1.0);
  f.n2 = glm::cross(f.n0, f.n1);
  return f;
}

RodFrame advance(const RodFrame& start, const glm::dvec3& darboux, double u) {
  Coefficients k = coefficients(glm::length(darboux), u);
  RodFrame f;
  glm::dvec3 wn0 = glm::cross(darboux, start.n0);
  f.position = start.position + u * start.n0 + k.b * wn0 + k.c * glm::cross(darboux, wn0);
  f.n0 = rotate(start.n0, darboux, k);
  f.n1 = rotate(start.n1, darboux, k);
  f.n2 = rotate(start.n2, darboux, k);
  return f;
}

RestShape restShape(double helixRadius, double helixStep) {
  if (helixRadius <= 0.0) return {};
  double c = helixStep / (2.0 * M_PI);
  double d = helixRadius * helixRadius + c * c;
  return {c / d, helixRadius / d, 0.0};
}

void sampleRod(const RodFrame& root, std::span<const double> lengths, std::span<const double> q,
               std::span<const double> s, std::vector<glm::dvec3>& positions, std::vector<glm::dvec3>* tangents) {
  positions.resize(s.size());
  if (tangents) tangents->resize(s.size());
  RodFrame start = root;
  double elementStart = 0.0;
  size_t i = 0;
  for (size_t e = 0; e < lengths.size(); ++e) {
    const double length = lengths[e];
    const glm::dvec3 w = darbouxVector(start, q[3 * e], q[3 * e + 1], q[3 * e + 2]);
    const bool last = e + 1 == lengths.size();
    for (; i < s.size() && (s[i] <= elementStart + length || last); ++i) {
      RodFrame f = advance(start, w, std::min(s[i] - elementStart, length));
      positions[i] = f.position;
      if (tangents) (*tangents)[i] = glm::normalize(f.n0);
    }
    start = advance(start, w, length);
    elementStart += length;
  }
}

double heightIntegral(const RodFrame& root, std::span<const double> lengths, std::span<const double> q) {
  // ∫0^L (r(s) − r0) ds = Σ_Q [ℓ_Q (r_Q(0) − r0) + ∫0^ℓ (r_Q(u) − r_Q(0)) du], and integrating the
  // centreline of the file comment over one element gives
  //   ∫0^ℓ (r_Q(u) − r_Q(0)) du = ℓ²/2 n0 + ib (W×n0) + ic (W×(W×n0)),
  //   ib = ∫0^ℓ b du = (x − sin x)/Ω³,   ic = ∫0^ℓ c du = (x²/2 − 1 + cos x)/Ω⁴.
  double total = 0.0;
  RodFrame start = root;
  for (size_t e = 0; e < lengths.size(); ++e) {
    const double l = lengths[e];
    const glm::dvec3 w = darbouxVector(start, q[3 * e], q[3 * e + 1], q[3 * e + 2]);
    const double omega = glm::length(w), x = omega * l;
    double ib, ic;
    if (std::abs(x) < kSeriesBelow) {
      double x2 = x * x;
      ib = l * l * l * (1.0 / 6.0 - x2 / 120.0 * (1.0 - x2 / 42.0 * (1.0 - x2 / 72.0)));
      ic = l * l * l * l * (1.0 / 24.0 - x2 / 720.0 * (1.0 - x2 / 56.0 * (1.0 - x2 / 90.0)));
    } else {
      double o2 = omega * omega;
      ib = (x - std::sin(x)) / (o2 * omega);
      ic = (0.5 * x * x - 1.0 + std::cos(x)) / (o2 * o2);
    }
    glm::dvec3 wn0 = glm::cross(w, start.n0);
    glm::dvec3 inner = 0.5 * l * l * start.n0 + ib * wn0 + ic * glm::cross(w, wn0);
    total += l * (start.position.y - root.position.y) + inner.y;
    start = advance(start, w, l);
  }
  return total;
}

std::vector<double> sampleArcLengths(double total, double step, bool includeRoot) {
  std::vector<double> s;
  if (includeRoot) s.push_back(0.0);
  size_t count = static_cast<size_t>(std::ceil(total / step - 1e-9));
  for (size_t i = 1; i < count; ++i) s.push_back(static_cast<double>(i) * step);
  s.push_back(total);
  return s;
}

}  // namespace hairgen
