// Super-Helix reconstruction, Lansink 2010 §4.1.1.2 (after Bertails et al. 2006).
//
// With W the Darboux vector, Ω = |W| and x = Ω·u, a vector v carried by the frame is
//   R(u)v = v + a(u)(W×v) + b(u)(W×(W×v)),    a = sin x / Ω,   b = (1 − cos x)/Ω²,
// and the centreline, the integral of the tangent, is
//   r(u) = r(0) + u n0 + b(u)(W×n0) + c(u)(W×(W×n0)),    c = (x − sin x)/Ω³.
// Written this way no coefficient divides by Ω once its series is used for small x.
#include "libcore/physics/super_helix.h"

#include <cmath>

namespace hairgen {
namespace {

HelixCoefficients coefficients(double omega, double invOmega, double u) {
  const double x = omega * u;
  if (std::abs(x) < kHelixSeriesBelow) return helixCoefficients(omega, invOmega, u, 1.0, 0.0);
  return helixCoefficients(omega, invOmega, u, std::cos(x), std::sin(x));
}

glm::dvec3 rotate(const glm::dvec3& v, const glm::dvec3& w, const HelixCoefficients& k) {
  const glm::dvec3 wv = glm::cross(w, v);
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

HelixElement::HelixElement(const RodFrame& start, const glm::dvec3& darboux, double length)
    : start_(start),
      w_(darboux),
      omega_(glm::length(darboux)),
      invOmega_(omega_ > 0.0 ? 1.0 / omega_ : 0.0),
      length_(length) {
  wn0_ = glm::cross(w_, start.n0);
  wwn0_ = glm::cross(w_, wn0_);
  const double x = omega_ * length;
  const bool series = std::abs(x) < kHelixSeriesBelow;
  sinL_ = series ? 0.0 : std::sin(x);
  cosL_ = series ? 1.0 : std::cos(x);
  const HelixCoefficients k = helixCoefficients(omega_, invOmega_, length, cosL_, sinL_);
  end_.position = along(length, k);
  end_.n0 = rotate(start.n0, w_, k);
  end_.n1 = rotate(start.n1, w_, k);
  end_.n2 = glm::cross(end_.n0, end_.n1);  // the frame stays right-handed; one rotation fewer
}

glm::dvec3 HelixElement::position(double u) const {
  return along(u, coefficients(omega_, invOmega_, u));
}

RodFrame HelixElement::frame(double u) const {
  const HelixCoefficients k = coefficients(omega_, invOmega_, u);
  RodFrame f;
  f.position = along(u, k);
  f.n0 = rotate(start_.n0, w_, k);
  f.n1 = rotate(start_.n1, w_, k);
  f.n2 = rotate(start_.n2, w_, k);
  return f;
}

glm::dvec3 HelixElement::displacementIntegral() const {
  // Integrating the centreline of the file comment over the element:
  //   ∫0^ℓ (r(u) − r(0)) du = ℓ²/2 n0 + ib (W×n0) + ic (W×(W×n0)),
  //   ib = ∫0^ℓ b du = (x − sin x)/Ω³,   ic = ∫0^ℓ c du = (x²/2 − 1 + cos x)/Ω⁴.
  const double l = length_;
  const double x = omega_ * l;
  double ib, ic;
  if (std::abs(x) < kHelixSeriesBelow) {
    const double x2 = x * x;
    ib = l * l * l * (1.0 / 6.0 - x2 / 120.0 * (1.0 - x2 / 42.0 * (1.0 - x2 / 72.0)));
    ic = l * l * l * l * (1.0 / 24.0 - x2 / 720.0 * (1.0 - x2 / 56.0 * (1.0 - x2 / 90.0)));
  } else {
    const double inv2 = invOmega_ * invOmega_;
    ib = (x - sinL_) * inv2 * invOmega_;
    ic = (0.5 * x * x - 1.0 + cosL_) * inv2 * inv2;
  }
  return 0.5 * l * l * start_.n0 + ib * wn0_ + ic * wwn0_;
}

RodFrame advance(const RodFrame& start, const glm::dvec3& darboux, double u) {
  return HelixElement(start, darboux, u).end();
}

RestShape restShape(double helixRadius, double helixStep) {
  if (helixRadius <= 0.0) return {};
  double c = helixStep / (2.0 * M_PI);
  double d = helixRadius * helixRadius + c * c;
  return {c / d, helixRadius / d, 0.0};
}

void sampleRod(const RodFrame& root, std::span<const double> lengths, std::span<const double> q,
               std::span<const double> s, std::vector<glm::dvec3>& positions,
               std::vector<glm::dvec3>* tangents) {
  positions.resize(s.size());
  if (tangents) tangents->resize(s.size());
  size_t i = 0;
  forEachElement(root, lengths, q, [&](const HelixElement& element, double elementStart, size_t e) {
    const double end = elementStart + element.length();
    const bool last = e + 1 == lengths.size();
    for (; i < s.size() && (s[i] <= end || last); ++i) {
      RodFrame f = element.frame(std::min(s[i] - elementStart, element.length()));
      positions[i] = f.position;
      if (tangents) (*tangents)[i] = glm::normalize(f.n0);
    }
  });
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
