// The keyed rigid motion of the head (Dynamics Info HeadKey), and the wind, as smooth functions of
// time: the pose moves the roots, the wick and every collision shape; its velocity and acceleration are
// what the hair feels in the head's frame.
//
// Each of the six channels (tx ty tz rx ry rz) is a quintic Hermite curve through the keys, with zero
// acceleration at each key and a monotone slope there (zero where the channel holds or turns back,
// else the harmonic mean of the neighbouring slopes, after Fritsch and Carlson), so a hold stays a hold,
// nothing overshoots, and velocity and acceleration are continuous everywhere. Before the first key the
// head is at the first key's pose; after the last, at the last's.
#pragma once

#include <array>
#include <vector>

#include <glm/glm.hpp>

#include "libcore/config/params.h"
#include "libcore/model/mesh.h"

namespace hairgen {

// A rigid motion about `centre`: x ↦ R(x − centre) + centre + t.
struct Pose {
  glm::dmat3 rotation{1.0};
  glm::dvec3 translation{0.0};
  glm::dvec3 centre{0.0};
  glm::dvec3 apply(const glm::dvec3& p) const { return rotation * (p - centre) + centre + translation; }
  glm::dmat4 matrix() const;  // the same as a 4×4 matrix
  bool isIdentity() const { return rotation == glm::dmat3(1.0) && translation == glm::dvec3(0.0); }
};

// The pose and its derivatives at an instant, all in world coordinates, per second.
struct HeadState {
  Pose pose;
  glm::dvec3 velocity{0.0}, acceleration{0.0};  // of the centre, m/s and m/s²
  glm::dvec3 omega{0.0}, alpha{0.0};            // angular velocity (rad/s) and acceleration (rad/s²)
};

class HeadMotion {
 public:
  HeadMotion() = default;
  HeadMotion(const std::vector<HeadKey>& keys, const glm::dvec3& centre, double frameRate);

  // At `frame` (fractional between frames; substeps are fractions of a frame).
  HeadState at(double frame) const;
  Pose pose(double frame) const { return at(frame).pose; }
  bool still() const { return keys_.empty(); }

 private:
  std::vector<HeadKey> keys_;
  std::vector<std::array<double, 6>> slopes_;  // per key and channel, per frame
  glm::dvec3 centre_{0.0};
  double frameRate_ = 24.0;
};

// The acceleration the hair feels in the head's frame, per substep: base (gravity, wind and the centre's
// acceleration, rotated into the head's frame), and the rotating frame's terms about `centre`.
struct AccelerationField {
  glm::dvec3 base{0.0};
  glm::dvec3 omega{0.0}, alpha{0.0};  // the head's angular velocity and acceleration, head frame
  glm::dvec3 centre{0.0};
  bool rotating = false;
  // At point r moving at v (head frame).
  glm::dvec3 at(const glm::dvec3& r, const glm::dvec3& v) const {
    if (!rotating) return base;
    const glm::dvec3 x = r - centre;
    return base - glm::cross(alpha, x) - glm::cross(omega, glm::cross(omega, x)) - 2.0 * glm::cross(omega, v);
  }
};

// The head-frame field at a state of the head: gravity (−y, `gravity` N/kg), the wind, and the head's
// acceleration, all turned into the head's frame.
AccelerationField headFrameField(const HeadState& head, const glm::dvec3& wind, double gravity);

// `mesh` moved by `pose`: positions, and normals turned with it.
Mesh posedMesh(const Mesh& mesh, const Pose& pose);

// Rz·Ry·Rx for rotations about x, y and z in degrees.
glm::dmat3 eulerRotation(const glm::dvec3& degrees);

// The wind's acceleration at `frame` (m/s²): zero before the first key.
glm::dvec3 windAt(const std::vector<WindKey>& keys, double frame);

// The head's centre for dynamics: HeadCentre, or the centre of headShape(collision), or the origin.
glm::dvec3 headCentre(const Dynamics& dynamics, const Collision& collision);

}  // namespace hairgen
