// Collision shapes fitted to a head: a least-squares sphere and an axis-aligned ellipsoid through the
// points of a cranium or a scalp (README, Real heads), for `Sphere v k auto` and `Ellipsoid v k auto`.
#pragma once

#include <vector>

#include <glm/glm.hpp>

namespace hairgen {

struct SphereFit {
  glm::dvec3 centre{0.0};  // metres
  double radius = 0.0;     // metres; 0 when fewer than four points span a volume
};

// The algebraic least-squares sphere (Kasa): minimises Σ (|p − c|² − r²)². Exact for points on a
// sphere; well posed for a cap of one (a scalp).
SphereFit fitSphere(const std::vector<glm::vec3>& points);

struct EllipsoidFit {
  glm::dvec3 centre{0.0};    // metres
  glm::dvec3 semiAxes{0.0};  // metres, along x, y, z
  bool valid = false;        // false when the points do not determine an ellipsoid (a flat or open patch)
};

// The algebraic least-squares ellipsoid with axes along x, y and z (a head stands up and faces +z):
// A x² + B y² + C z² + D x + E y + F z = 1 in coordinates about the points' mean.
EllipsoidFit fitAlignedEllipsoid(const std::vector<glm::vec3>& points);

// A collision body for a head: the cranium of `head` (its points within kCraniumHeight of its top; of
// `roots` when `head` is empty, e.g. a scalp or a whole head as the wick), fitted as an ellipsoid, or as a
// sphere when `sphere` or when the ellipsoid fit is not a head-like one (a semi-axis beyond 0.6-1.6 times the
// sphere's radius). It is then scaled about its centre so that all but kRootsInside of the roots on the
// cranium lie on or outside it: hair must start outside the body that pushes it out.
struct HeadFit {
  glm::dvec3 centre{0.0};
  glm::dvec3 semiAxes{0.0};  // all equal for a sphere
  bool ellipsoid = false;
};
inline constexpr double kCraniumHeight = 0.12;  // metres from the top: above the ears and the brow
inline constexpr double kRootsInside = 0.05;    // roots allowed inside the fitted body (scan noise)
HeadFit fitHead(const std::vector<glm::vec3>& head, const std::vector<glm::vec3>& roots, bool sphere);

}  // namespace hairgen
