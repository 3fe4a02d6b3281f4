// The camera's and the light's views of a scene, and the sphere that bounds it. Pure math: no OpenGL.
// Right-handed, metres; a view looks along its −z.
#pragma once

#include <glm/glm.hpp>

#include "libcore/config/params.h"
#include "libcore/model/mesh.h"
#include "libcore/model/strands.h"

namespace hairgen {

// A pinhole view onto a width × height image.
struct View {
  glm::dmat4 view{1.0}, proj{1.0};  // world to view, view to clip
  double focalPx = 1.0;             // pixels per metre at one metre of depth
  int width = 1, height = 1;        // pixels
};

struct BoundingSphere {
  glm::dvec3 centre{0.0};  // metres
  double radius = 0.0;     // metres
};

// The sphere around the bounding box of the hair's points and the head's vertices (`head` may be
// null): at least 1 mm in radius; centred on the origin with radius 0.1 m when there are no points.
BoundingSphere boundingSphere(const Strands& hair, const Mesh* head);

// The Render Info camera (CameraPosition, CameraTarget, CameraUp, FieldOfView vertical, Resolution),
// its near and far planes hugging `scene`.
View cameraView(const RenderSettings& render, const BoundingSphere& scene);

// From LightPosition toward the scene's centre, a size × size view whose field just holds `scene`
// (120° when the light is inside it).
View lightView(const RenderSettings& render, const BoundingSphere& scene, int size);

// The same camera on a grid of block × block sub-pixels per pixel.
View subpixelView(const View& camera, int block);

}  // namespace hairgen
