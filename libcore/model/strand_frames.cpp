// Parallel-transport frames along strands, and normals re-posed through them (Petrovic et al. 2005 §4:
// the rest pose's shading normals carried onto animated hair).
#include "libcore/model/strand_frames.h"

#include <algorithm>
#include <cmath>

#include "libcore/util/error.h"

namespace hairgen {

glm::dvec3 transport(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& v) {
  glm::dvec3 axis = glm::cross(a, b);
  double s = glm::length(axis), c = glm::dot(a, b);
  if (s < 1e-14) return c > 0.0 ? v : -v;
  axis /= s;
  return v * c + glm::cross(axis, v) * s + axis * glm::dot(axis, v) * (1.0 - c);
}

std::vector<glm::vec3> transportFrames(const Strands& s) {
  const PointArray tangents = tangentsOf(s);
  glm::dvec3 centroid(0.0);
  for (size_t i = 0; i < s.strandCount(); ++i) centroid += glm::dvec3(s.points[s.firstPoint[i]]);
  centroid /= double(std::max<size_t>(s.strandCount(), 1));
  std::vector<glm::vec3> u(s.pointCount());
  for (size_t i = 0; i < s.strandCount(); ++i) {
    const uint32_t first = s.firstPoint[i], last = s.firstPoint[i + 1];
    if (first == last) continue;
    glm::dvec3 t = glm::normalize(glm::dvec3(tangents[first]));
    glm::dvec3 ref = centroid - glm::dvec3(s.points[first]);
    glm::dvec3 frame = ref - glm::dot(ref, t) * t;
    if (glm::length(frame) < 1e-9)
      frame = glm::cross(t, std::abs(t.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0));
    frame = glm::normalize(frame);
    u[first] = glm::vec3(frame);
    for (uint32_t p = first + 1; p < last; ++p) {
      glm::dvec3 next = glm::normalize(glm::dvec3(tangents[p]));
      frame = glm::normalize(transport(t, next, frame));
      frame = glm::normalize(frame - glm::dot(frame, next) * next);
      t = next;
      u[p] = glm::vec3(frame);
    }
  }
  return u;
}

std::vector<glm::vec3> reposeNormals(const Strands& rest, const Strands& deformed) {
  if (rest.strandCount() != deformed.strandCount() || rest.firstPoint != deformed.firstPoint)
    throw InputError("the rest coupe and the coupe to re-pose differ in strands or vertex counts");
  if (rest.normals.empty()) throw InputError("the rest coupe has no normals; run hairgen shade on it first");
  const PointArray tr = tangentsOf(rest), td = tangentsOf(deformed);
  const std::vector<glm::vec3> ur = transportFrames(rest), ud = transportFrames(deformed);
  std::vector<glm::vec3> out(deformed.pointCount());
  for (size_t p = 0; p < out.size(); ++p) {
    glm::dvec3 t(glm::normalize(tr[p])), u(ur[p]), v = glm::cross(t, u);
    glm::dvec3 n(rest.normals[p]);
    glm::dvec3 local(glm::dot(n, t), glm::dot(n, u), glm::dot(n, v));
    glm::dvec3 t2(glm::normalize(td[p])), u2(ud[p]), v2 = glm::cross(t2, u2);
    out[p] = glm::vec3(glm::normalize(local.x * t2 + local.y * u2 + local.z * v2));
  }
  return out;
}

}  // namespace hairgen
