#include "libcore/render/views.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>

namespace hairgen {

namespace {

// `preferred`, or +z when it is parallel to the view direction (lookAt needs an up off that axis).
glm::dvec3 anyUp(const glm::dvec3& forward, const glm::dvec3& preferred) {
  return std::abs(glm::dot(glm::normalize(forward), glm::normalize(preferred))) > 0.999 ? glm::dvec3(0, 0, 1)
                                                                                        : preferred;
}

}  // namespace

BoundingSphere boundingSphere(const Strands& hair, const Mesh* head) {
  std::vector<glm::vec3> corners;
  for (const std::span<const glm::vec3> points :
       {std::span<const glm::vec3>(hair.points),
        head ? std::span<const glm::vec3>(head->positions) : std::span<const glm::vec3>()})
    if (!points.empty()) {
      const Bounds b = bounds(points);
      corners.insert(corners.end(), {b.min, b.max});
    }
  if (corners.empty()) return {glm::dvec3(0.0), 0.1};
  const Bounds box = bounds(corners);
  const glm::dvec3 lo(box.min), hi(box.max);
  return {(lo + hi) * 0.5, std::max(glm::length(hi - lo) * 0.5, 1e-3)};
}

View cameraView(const RenderSettings& r, const BoundingSphere& scene) {
  View v;
  v.width = r.resolution.x;
  v.height = r.resolution.y;
  glm::dvec3 forward = r.cameraTarget - r.cameraPosition;
  v.view = glm::lookAt(r.cameraPosition, r.cameraTarget, anyUp(forward, r.cameraUp));
  double distance = glm::length(scene.centre - r.cameraPosition);
  double nearPlane = std::max(distance - scene.radius, 1e-3 * std::max(distance, 1e-3));
  double farPlane = distance + scene.radius * 1.01 + 1e-3;
  double fov = glm::radians(r.fieldOfView);
  v.proj = glm::perspective(fov, double(v.width) / v.height, nearPlane, farPlane);
  v.focalPx = 0.5 * v.height / std::tan(0.5 * fov);
  return v;
}

View lightView(const RenderSettings& r, const BoundingSphere& scene, int size) {
  View v;
  v.width = v.height = size;
  glm::dvec3 forward = scene.centre - r.lightPosition;
  double distance = glm::length(forward);
  v.view = glm::lookAt(r.lightPosition, scene.centre, anyUp(forward, glm::dvec3(0, 1, 0)));
  double fov =
      distance > scene.radius * 1.05 ? 2.0 * std::asin(scene.radius / distance) * 1.02 : glm::radians(120.0);
  double nearPlane = std::max(distance - scene.radius * 1.01, 1e-3 * std::max(distance, 1e-3));
  v.proj = glm::perspective(fov, 1.0, nearPlane, distance + scene.radius * 1.01 + 1e-3);
  v.focalPx = 0.5 * size / std::tan(0.5 * fov);
  return v;
}

glm::dmat4 openExrWorldToCamera(const View& v) {
  // OpenGL's view space looks along −z: turning z round makes it OpenEXR's (and RenderMan's) camera.
  return glm::scale(glm::dmat4(1.0), glm::dvec3(1.0, 1.0, -1.0)) * v.view;
}

glm::dmat4 openExrWorldToNdc(const View& v) {
  // Clip space to OpenEXR's NDC before the divide: x' = (x + w)/2, y' = (w − y)/2, so after it
  // OpenGL's [−1, 1] with y up becomes [0, 1] with y down; z and w are kept.
  glm::dmat4 toNdc(1.0);
  toNdc[0][0] = 0.5;
  toNdc[1][1] = -0.5;
  toNdc[3][0] = 0.5;  // column 3 multiplies w
  toNdc[3][1] = 0.5;
  return toNdc * v.proj * v.view;
}

View subpixelView(const View& camera, int block) {
  View fine = camera;
  fine.width = camera.width * block;
  fine.height = camera.height * block;
  fine.focalPx = camera.focalPx * block;
  return fine;
}

int subpixelBlock(const RenderSettings& render, int maxTextureSize) {
  int block = std::clamp(int(std::lround(std::sqrt(double(render.samples)))), 1, 8);
  while (block > 1 && std::max(render.resolution.x, render.resolution.y) * block > maxTextureSize) --block;
  return block;
}

}  // namespace hairgen
