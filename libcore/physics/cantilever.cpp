// Cantilever-beam styling, Anjyo, Usami and Kurihara 1992, §2.1-2.2 and §3.2.3.
#include "libcore/physics/cantilever.h"

#include <cmath>

namespace hairgen {
namespace {

// Inside the ellipsoid when the normalised local radius is below 1 (the sign of its quadric form).
double ellipsoidRadius(const CollisionShape& e, const glm::dvec3& p) {
  glm::dvec3 v = p - e.centre;
  glm::dvec3 local(glm::dot(v, e.axes[0]), glm::dot(v, e.axes[1]), glm::dot(v, e.axes[2]));
  return glm::length(local / e.halfExtents);
}

glm::dvec3 ellipsoidGradient(const CollisionShape& e, const glm::dvec3& p) {
  glm::dvec3 v = p - e.centre;
  glm::dvec3 local(glm::dot(v, e.axes[0]), glm::dot(v, e.axes[1]), glm::dot(v, e.axes[2]));
  glm::dvec3 g = local / (e.halfExtents * e.halfExtents);
  return g.x * e.axes[0] + g.y * e.axes[1] + g.z * e.axes[2];
}

// Rotates unit `dir` toward unit `target` by `angle` radians in their plane (or not at all when they
// are parallel).
glm::dvec3 turnToward(const glm::dvec3& dir, const glm::dvec3& target, double angle) {
  glm::dvec3 ortho = target - glm::dot(target, dir) * dir;
  double len = glm::length(ortho);
  if (len < 1e-12) return dir;
  ortho /= len;
  return std::cos(angle) * dir + std::sin(angle) * ortho;
}

double angleBetween(const glm::dvec3& a, const glm::dvec3& b) {
  return std::atan2(glm::length(glm::cross(a, b)), glm::dot(a, b));
}

}  // namespace

double cantileverDeflection(double load, double d, double rigidity, int k, int i) {
  const double span = double(k - i + 1);
  const double moment = -load * d * span * span / 2.0;  // (2)
  return -0.5 * (moment / rigidity) * d * d;            // (3)
}

std::vector<glm::dvec3> bendHair(const glm::dvec3& pore, const glm::dvec3& normal, const Hairstyle& style,
                                 const CollisionShape* head) {
  const int k = style.segments;
  const double length = style.totalLength(), d = length / k;
  const double a = style.hairRadius1, b = style.hairRadius2;
  const double rigidity =
      style.flexuralRigidity > 0.0 ? style.flexuralRigidity : style.young * M_PI * a * b * b * b / 4.0;
  const double massPerLength = style.massDensity * M_PI * a * b;
  const double limit = glm::radians(style.jointLimit);
  std::vector<glm::dvec3> p{pore};
  glm::dvec3 a0 = glm::normalize(normal);  // the direction of the segment before: the follicle's at the pore
  for (int i = 1; i <= k; ++i) {
    const glm::dvec3& start = p.back();
    // The load on this segment: gravity and every force field whose region holds the segment's start.
    glm::dvec3 acceleration(0.0, -style.gravity, 0.0);
    for (const ForceField& f : style.forces)
      if (f.contains(start)) acceleration += f.acceleration;
    // Split across a0 (a1, a2 span the plane normal to it); no compression along a0.
    glm::dvec3 across = acceleration - glm::dot(acceleration, a0) * a0;
    double magnitude = glm::length(across);
    glm::dvec3 deflection(0.0);
    if (magnitude > 0.0) {
      const glm::dvec3 a1 = across / magnitude;
      const glm::dvec3 a2 = glm::cross(a0, a1);
      const double y1 =
          cantileverDeflection(massPerLength * d * glm::dot(acceleration, a1), d, rigidity, k, i);
      const double y2 =
          cantileverDeflection(massPerLength * d * glm::dot(acceleration, a2), d, rigidity, k, i);
      deflection = y1 * a1 + y2 * a2;
    }
    glm::dvec3 dir = glm::normalize(d * a0 + deflection);
    // Joint stiffness (§3.2.3): the turn at node i − 1 is at most σ.
    if (i - 1 >= style.jointLimitFrom && limit < M_PI) {
      double turn = angleBetween(a0, dir);
      if (turn > limit) dir = turnToward(a0, dir, limit);
    }
    // Collision avoidance (§2.1): a node inside the head is moved out, in the plane of the last two
    // nodes and the new one, as near its place as bisection on the turn finds.
    if (head && ellipsoidRadius(*head, start + d * dir) < 1.0) {
      glm::dvec3 out = glm::normalize(ellipsoidGradient(*head, start));
      glm::dvec3 plane = glm::cross(a0, dir);
      if (glm::length(plane) > 1e-9) {
        plane = glm::normalize(plane);
        glm::dvec3 inPlane = out - glm::dot(out, plane) * plane;
        if (glm::length(inPlane) > 1e-6) out = glm::normalize(inPlane);
      }
      const double full = angleBetween(dir, out);
      double lo = 0.0, hi = full;
      if (ellipsoidRadius(*head, start + d * turnToward(dir, out, hi)) >= 1.0) {
        for (int it = 0; it < 40; ++it) {
          double mid = 0.5 * (lo + hi);
          (ellipsoidRadius(*head, start + d * turnToward(dir, out, mid)) >= 1.0 ? hi : lo) = mid;
        }
      }
      dir = turnToward(dir, out, hi);
    }
    p.push_back(start + d * dir);
    a0 = dir;
  }
  return p;
}

glm::dvec2 porePolar(const glm::dvec3& pore, const CollisionShape* head) {
  glm::dvec3 v = head ? pore - head->centre : pore;
  glm::dvec3 local =
      head ? glm::dvec3(glm::dot(v, head->axes[0]), glm::dot(v, head->axes[1]), glm::dot(v, head->axes[2])) /
                 head->halfExtents
           : v;
  double azimuth = glm::degrees(std::atan2(local.x, local.z));
  double zenith = glm::degrees(std::atan2(std::hypot(local.x, local.z), local.y));
  return {azimuth, zenith};
}

size_t cutHair(std::vector<glm::dvec3>& nodes, const Hairstyle& style, const CollisionShape* head) {
  if (nodes.empty()) return 0;
  const glm::dvec2 polar = porePolar(nodes.front(), head);
  for (const HairCut& c : style.cuts) {
    if (polar.x < c.azimuthFrom || polar.x > c.azimuthTo || polar.y > c.zenithMax) continue;
    for (size_t i = 1; i < nodes.size(); ++i)
      if (nodes[i].y < c.height) {
        nodes.resize(i);
        break;
      }
  }
  return nodes.size();
}

}  // namespace hairgen
