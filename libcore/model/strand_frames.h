// Frames carried along strands by parallel transport, and shading normals re-posed through them onto a
// deformed coupe of the same strands (Petrovic et al. 2005 §4, for animated hair).
#pragma once

#include <vector>

#include <glm/glm.hpp>

#include "libcore/model/strands.h"

namespace hairgen {

// The minimal rotation taking unit a to unit b, applied to v (v itself when a and b agree, −v when they
// are opposite).
glm::dvec3 transport(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& v);

// The same rotation by Rodrigues' formula in a × b and a · b, with no square root: v cos + (w × v) +
// w (w · v) / (1 + cos), w = a × b. For what turns every vertex of every frame; not bit for bit
// `transport` (which the stored shading frames keep).
inline glm::dvec3 transportFast(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& v) {
  const glm::dvec3 w = glm::cross(a, b);
  const double c = glm::dot(a, b);
  if (c < -1.0 + 1e-12) return -v;  // opposite: any half turn; transport's
  return c * v + glm::cross(w, v) + w * (glm::dot(w, v) / (1.0 + c));
}

// Parallel-transport frames: at the root (t, u, t×u) with u the direction from the root toward the
// centroid of all roots, made normal to t (fixed to the follicle and moving rigidly with the coupe),
// then carried vertex to vertex by the minimal rotation between tangents. Returns u per vertex.
std::vector<glm::vec3> transportFrames(const Strands& strands);

// Re-poses the rest coupe's normals onto a deformed coupe of the same strands and vertex counts: each
// normal is written in its rest frame and read back in the deformed one.
std::vector<glm::vec3> reposeNormals(const Strands& rest, const Strands& deformed);

}  // namespace hairgen
