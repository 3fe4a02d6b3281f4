#include "stages/render.h"

#include <algorithm>
#include <cmath>

#include "libcore/render/views.h"

namespace hairgen {

void conform(Strands& hair, bool zUp, double scale) {
  const float s = static_cast<float>(scale);
  auto fix = [&](glm::vec3 v, bool position) {
    if (zUp) v = glm::vec3(v.x, v.z, -v.y);
    return position ? v * s : v;
  };
  for (glm::vec3& p : hair.points) p = fix(p, true);
  for (glm::vec3& t : hair.tangents) t = fix(t, false);
  for (glm::vec3& n : hair.normals) n = fix(n, false);
  for (float& t : hair.thickness) t *= s;
  hair.defaultThickness *= s;
}

void frameHair(RenderSettings& r, const Strands& hair) {
  if (hair.points.empty()) return;
  const BoundingSphere sphere = boundingSphere(hair, nullptr);
  const double fov = glm::radians(r.fieldOfView) * std::min(1.0, double(r.resolution.x) / r.resolution.y);
  const double distance = sphere.radius / std::sin(0.5 * fov) * 1.05;
  const glm::dvec3 view = r.cameraPosition - r.cameraTarget, toLight = r.lightPosition - r.cameraTarget;
  const double lightRatio = glm::length(toLight) / std::max(glm::length(view), 1e-9);
  r.cameraTarget = sphere.centre;
  r.cameraPosition = sphere.centre + glm::normalize(view) * distance;
  r.lightPosition = sphere.centre + glm::normalize(toLight) * distance * lightRatio;
}

RenderOutput render(GlContext& gl, const Strands& hair, const Mesh* head, const Visuality& visuality,
                    const RenderSettings& settings, const CustomShaders& shaders,
                    const RenderOptions& options) {
  // Hair made elsewhere is conformed in a copy; hairgen's own is rendered as it is.
  std::optional<Strands> conformed;
  if (options.zUp || options.scale != 1.0) {
    conformed = hair;
    conform(*conformed, options.zUp, options.scale);
  }
  RenderInput input;
  input.hair = conformed ? &*conformed : &hair;
  input.head = head;
  input.visuality = visuality;
  input.settings = settings;
  if (options.frame) frameHair(input.settings, *input.hair);
  input.shaders = shaders;
  input.domResolution =
      options.domResolution > 0 ? options.domResolution : domResolutionFor(settings.resolution);
  input.keepDom = options.keepDom;
  return renderHair(gl, input);
}

}  // namespace hairgen
