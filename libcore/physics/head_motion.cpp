#include "libcore/physics/head_motion.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace hairgen {
namespace {

// Quintic Hermite basis on [0, 1] with zero second derivatives at both ends: value, first and second
// derivative with respect to t of h00 (start value), h01 (end value), h10 (start slope), h11 (end slope).
struct Basis {
  double h00, h01, h10, h11;
};
Basis basis(double t, int derivative) {
  const double t2 = t * t, t3 = t2 * t, t4 = t3 * t, t5 = t4 * t;
  switch (derivative) {
    case 0:
      return {1 - 10 * t3 + 15 * t4 - 6 * t5, 10 * t3 - 15 * t4 + 6 * t5, t - 6 * t3 + 8 * t4 - 3 * t5,
              -4 * t3 + 7 * t4 - 3 * t5};
    case 1:
      return {-30 * t2 + 60 * t3 - 30 * t4, 30 * t2 - 60 * t3 + 30 * t4, 1 - 18 * t2 + 32 * t3 - 15 * t4,
              -12 * t2 + 28 * t3 - 15 * t4};
    default:
      return {-60 * t + 180 * t2 - 120 * t3, 60 * t - 180 * t2 + 120 * t3, -36 * t + 96 * t2 - 60 * t3,
              -24 * t + 84 * t2 - 60 * t3};
  }
}

double channel(const HeadKey& k, int c) {
  return c < 3 ? k.translation[c] : k.rotation[c - 3];
}

}  // namespace

glm::dmat4 Pose::matrix() const {
  glm::dmat4 m(rotation);
  m[3] = glm::dvec4(centre + translation - rotation * centre, 1.0);
  return m;
}

Mesh posedMesh(const Mesh& mesh, const Pose& pose) {
  Mesh out = mesh;
  for (glm::vec3& p : out.positions) p = glm::vec3(pose.apply(glm::dvec3(p)));
  for (glm::vec3& n : out.normals) n = glm::vec3(pose.rotation * glm::dvec3(n));
  return out;
}

glm::dmat3 eulerRotation(const glm::dvec3& degrees) {
  const glm::dvec3 r = glm::radians(degrees);
  const double cx = std::cos(r.x), sx = std::sin(r.x), cy = std::cos(r.y), sy = std::sin(r.y);
  const double cz = std::cos(r.z), sz = std::sin(r.z);
  const glm::dmat3 rx(1, 0, 0, 0, cx, sx, 0, -sx, cx);  // columns
  const glm::dmat3 ry(cy, 0, -sy, 0, 1, 0, sy, 0, cy);
  const glm::dmat3 rz(cz, sz, 0, -sz, cz, 0, 0, 0, 1);
  return rz * ry * rx;
}

HeadMotion::HeadMotion(const std::vector<HeadKey>& keys, const glm::dvec3& centre, double frameRate)
    : keys_(keys), centre_(centre), frameRate_(frameRate) {
  std::stable_sort(keys_.begin(), keys_.end(),
                   [](const HeadKey& a, const HeadKey& b) { return a.frame < b.frame; });
  slopes_.assign(keys_.size(), {0, 0, 0, 0, 0, 0});
  for (size_t j = 1; j + 1 < keys_.size(); ++j)
    for (int c = 0; c < 6; ++c) {
      const double before =
          (channel(keys_[j], c) - channel(keys_[j - 1], c)) / (keys_[j].frame - keys_[j - 1].frame);
      const double after =
          (channel(keys_[j + 1], c) - channel(keys_[j], c)) / (keys_[j + 1].frame - keys_[j].frame);
      // A hold or a turning point keeps zero slope; otherwise the harmonic mean, which never overshoots.
      slopes_[j][c] = before * after > 0.0 ? 2.0 / (1.0 / before + 1.0 / after) : 0.0;
    }
}

HeadState HeadMotion::at(double frame) const {
  HeadState s;
  s.pose.centre = centre_;
  if (keys_.empty()) return s;
  // The six channels and their first and second derivatives per frame.
  std::array<double, 6> value{}, d1{}, d2{};
  if (frame <= keys_.front().frame || frame >= keys_.back().frame || keys_.size() == 1) {
    const HeadKey& k = frame <= keys_.front().frame ? keys_.front() : keys_.back();
    for (int c = 0; c < 6; ++c) value[c] = channel(k, c);
  } else {
    size_t j = size_t(std::upper_bound(keys_.begin(), keys_.end(), frame,
                                       [](double f, const HeadKey& k) { return f < k.frame; }) -
                      keys_.begin()) -
               1;
    const HeadKey &a = keys_[j], &b = keys_[j + 1];
    const double h = b.frame - a.frame, t = (frame - a.frame) / h;
    const Basis b0 = basis(t, 0), b1 = basis(t, 1), b2 = basis(t, 2);
    for (int c = 0; c < 6; ++c) {
      const double p0 = channel(a, c), p1 = channel(b, c), m0 = slopes_[j][c], m1 = slopes_[j + 1][c];
      value[c] = b0.h00 * p0 + b0.h01 * p1 + h * (b0.h10 * m0 + b0.h11 * m1);
      d1[c] = (b1.h00 * p0 + b1.h01 * p1) / h + (b1.h10 * m0 + b1.h11 * m1);
      d2[c] = (b2.h00 * p0 + b2.h01 * p1) / (h * h) + (b2.h10 * m0 + b2.h11 * m1) / h;
    }
  }
  const double f = frameRate_, f2 = f * f, toRad = M_PI / 180.0;
  s.pose.translation = {value[0], value[1], value[2]};
  s.pose.rotation = eulerRotation({value[3], value[4], value[5]});
  s.velocity = glm::dvec3(d1[0], d1[1], d1[2]) * f;
  s.acceleration = glm::dvec3(d2[0], d2[1], d2[2]) * f2;
  // R = Rz(c) Ry(b) Rx(a): ω = c' z + b' Rz y + a' Rz Ry x, and its derivative.
  const double da = d1[3] * toRad * f, db = d1[4] * toRad * f, dc = d1[5] * toRad * f;
  const double dda = d2[3] * toRad * f2, ddb = d2[4] * toRad * f2, ddc = d2[5] * toRad * f2;
  const glm::dmat3 rz = eulerRotation({0.0, 0.0, value[5]});
  const glm::dmat3 rzy = rz * eulerRotation({0.0, value[4], 0.0});
  const glm::dvec3 z(0, 0, 1), yAxis = rz * glm::dvec3(0, 1, 0), xAxis = rzy * glm::dvec3(1, 0, 0);
  const glm::dvec3 omegaZ = dc * z, omegaZY = omegaZ + db * yAxis;
  s.omega = omegaZY + da * xAxis;
  s.alpha =
      ddc * z + ddb * yAxis + db * glm::cross(omegaZ, yAxis) + dda * xAxis + da * glm::cross(omegaZY, xAxis);
  return s;
}

AccelerationField headFrameField(const HeadState& head, const glm::dvec3& wind, double gravity) {
  AccelerationField f;
  const glm::dmat3 toHead = glm::transpose(head.pose.rotation);
  f.base = toHead * (glm::dvec3(0.0, -gravity, 0.0) + wind - head.acceleration);
  f.omega = toHead * head.omega;
  f.alpha = toHead * head.alpha;
  f.centre = head.pose.centre;
  f.rotating = f.omega != glm::dvec3(0.0) || f.alpha != glm::dvec3(0.0);
  return f;
}

glm::dvec3 windAt(const std::vector<WindKey>& keys, double frame) {
  glm::dvec3 wind(0.0);
  for (size_t j = 0; j < keys.size(); ++j) {
    if (keys[j].frame <= frame) {
      wind = keys[j].acceleration;
      continue;
    }
    // The first key after `frame`: a linear key ramps toward it from the previous one.
    if (keys[j].linear && j > 0) {
      const double t = (frame - keys[j - 1].frame) / (keys[j].frame - keys[j - 1].frame);
      wind = keys[j - 1].acceleration + t * (keys[j].acceleration - keys[j - 1].acceleration);
    }
    break;
  }
  return wind;
}

glm::dvec3 headCentre(const Dynamics& dynamics, const Collision& collision) {
  if (!dynamics.headCentreAuto) return dynamics.headCentre;
  const CollisionShape* head = headShape(collision);
  return head ? head->centre : glm::dvec3(0.0);
}

}  // namespace hairgen
