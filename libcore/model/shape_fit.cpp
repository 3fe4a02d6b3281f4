// Least-squares sphere and ellipsoid fits by their algebraic distance (Kasa 1976; the axis-aligned
// quadric form of Li & Griffiths 2004 without the general cross terms): linear in the unknowns, so one
// small normal-equation solve, with coordinates about the mean and scaled to unit size for conditioning.
#include "libcore/model/shape_fit.h"

#include <algorithm>
#include <cmath>

namespace hairgen {
namespace {

// Solves the N×N system M x = b by Gaussian elimination with partial pivoting; false when singular.
template <int N>
bool solve(double m[N][N], double b[N], double x[N]) {
  for (int c = 0; c < N; ++c) {
    int pivot = c;
    for (int r = c + 1; r < N; ++r)
      if (std::abs(m[r][c]) > std::abs(m[pivot][c])) pivot = r;
    if (!(std::abs(m[pivot][c]) > 1e-12)) return false;
    std::swap(m[c], m[pivot]);
    std::swap(b[c], b[pivot]);
    for (int r = c + 1; r < N; ++r) {
      const double f = m[r][c] / m[c][c];
      for (int k = c; k < N; ++k) m[r][k] -= f * m[c][k];
      b[r] -= f * b[c];
    }
  }
  for (int c = N - 1; c >= 0; --c) {
    double s = b[c];
    for (int k = c + 1; k < N; ++k) s -= m[c][k] * x[k];
    x[c] = s / m[c][c];
  }
  return true;
}

struct Normalised {
  glm::dvec3 mean{0.0};
  double scale = 1.0;
  std::vector<glm::dvec3> points;
};

Normalised normalise(const std::vector<glm::vec3>& points) {
  Normalised n;
  for (const glm::vec3& p : points) n.mean += glm::dvec3(p);
  n.mean /= double(std::max<size_t>(points.size(), 1));
  double spread = 0.0;
  for (const glm::vec3& p : points) spread = std::max(spread, glm::length(glm::dvec3(p) - n.mean));
  n.scale = spread > 0.0 ? spread : 1.0;
  n.points.reserve(points.size());
  for (const glm::vec3& p : points) n.points.push_back((glm::dvec3(p) - n.mean) / n.scale);
  return n;
}

}  // namespace

SphereFit fitSphere(const std::vector<glm::vec3>& points) {
  SphereFit fit;
  if (points.size() < 4) return fit;
  const Normalised n = normalise(points);
  // |p|² = 2 c·p + d, d = r² − |c|².
  double m[4][4] = {}, b[4] = {}, x[4] = {};
  for (const glm::dvec3& p : n.points) {
    const double row[4] = {2 * p.x, 2 * p.y, 2 * p.z, 1.0}, rhs = glm::dot(p, p);
    for (int i = 0; i < 4; ++i) {
      for (int j = 0; j < 4; ++j) m[i][j] += row[i] * row[j];
      b[i] += row[i] * rhs;
    }
  }
  if (!solve<4>(m, b, x)) return fit;
  const glm::dvec3 c(x[0], x[1], x[2]);
  const double r2 = x[3] + glm::dot(c, c);
  if (!(r2 > 0.0)) return fit;
  fit.centre = n.mean + n.scale * c;
  fit.radius = n.scale * std::sqrt(r2);
  return fit;
}

EllipsoidFit fitAlignedEllipsoid(const std::vector<glm::vec3>& points) {
  EllipsoidFit fit;
  if (points.size() < 6) return fit;
  const Normalised n = normalise(points);
  double m[6][6] = {}, b[6] = {}, x[6] = {};
  for (const glm::dvec3& p : n.points) {
    const double row[6] = {p.x * p.x, p.y * p.y, p.z * p.z, p.x, p.y, p.z};
    for (int i = 0; i < 6; ++i) {
      for (int j = 0; j < 6; ++j) m[i][j] += row[i] * row[j];
      b[i] += row[i];
    }
  }
  if (!solve<6>(m, b, x)) return fit;
  if (!(x[0] > 0.0 && x[1] > 0.0 && x[2] > 0.0)) return fit;
  // A (x − cx)² + B (y − cy)² + C (z − cz)² = G.
  const glm::dvec3 quad(x[0], x[1], x[2]), lin(x[3], x[4], x[5]);
  const glm::dvec3 c = -lin / (2.0 * quad);
  const double g = 1.0 + glm::dot(quad, c * c);
  if (!(g > 0.0)) return fit;
  fit.centre = n.mean + n.scale * c;
  fit.semiAxes = n.scale * glm::sqrt(glm::dvec3(g) / quad);
  fit.valid = std::isfinite(fit.semiAxes.x) && std::isfinite(fit.semiAxes.y) && std::isfinite(fit.semiAxes.z);
  return fit;
}

HeadFit fitHead(const std::vector<glm::vec3>& head, const std::vector<glm::vec3>& roots, bool sphere) {
  // The cranium: the points near the top, whether of a head or of a wick that is a whole head.
  auto cranium = [](const std::vector<glm::vec3>& points) {
    float top = -HUGE_VALF;
    for (const glm::vec3& p : points) top = std::max(top, p.y);
    std::vector<glm::vec3> out;
    for (const glm::vec3& p : points)
      if (p.y >= top - float(kCraniumHeight)) out.push_back(p);
    return out;
  };
  const std::vector<glm::vec3> scalp = cranium(roots), points = head.empty() ? scalp : cranium(head);
  HeadFit fit;
  const SphereFit s = fitSphere(points);
  fit.centre = s.centre;
  fit.semiAxes = glm::dvec3(s.radius);
  if (!sphere) {
    const EllipsoidFit e = fitAlignedEllipsoid(points);
    const glm::dvec3 ratio = e.semiAxes / std::max(s.radius, 1e-12);
    if (e.valid && glm::all(glm::greaterThan(ratio, glm::dvec3(0.6))) &&
        glm::all(glm::lessThan(ratio, glm::dvec3(1.6)))) {
      fit.centre = e.centre;
      fit.semiAxes = e.semiAxes;
    }
    fit.ellipsoid = true;
  }
  if (!(s.radius > 0.0) || scalp.empty()) return fit;
  // Each root's ellipsoidal radius (1 on the surface), over the roots on the cranium: hair on a face or
  // a neck is not what the body holds off.
  std::vector<double> radii;
  radii.reserve(scalp.size());
  for (const glm::vec3& p : scalp) radii.push_back(glm::length((glm::dvec3(p) - fit.centre) / fit.semiAxes));
  const size_t k = size_t(kRootsInside * double(radii.size()));
  std::nth_element(radii.begin(), radii.begin() + k, radii.end());
  const double shrink = radii[k];
  if (shrink > 0.0 && shrink < 1.0) fit.semiAxes *= shrink;
  return fit;
}

}  // namespace hairgen
