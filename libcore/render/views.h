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

// OpenEXR's camera attributes of a view (ImfStandardAttributes.h), as glm matrices for column vectors
// (p' = M p; the EXR writer transposes them for Imath's row vectors, p' = p M):
//   worldToCamera: world to camera space, left-handed, +x right and +y up in the image, +z the viewing
//                  direction, so a point in front of the camera has z > 0 (its distance along the axis,
//                  the Z channel); metres.
//   worldToNdc:    world to NDC, x right and y down, (0, 0) the image's top-left corner and (1, 1) its
//                  bottom-right, after the divide by w: pixel (x, y)'s centre is at ((x + ½)/W, (y + ½)/H).
glm::dmat4 openExrWorldToCamera(const View& view);
glm::dmat4 openExrWorldToNdc(const View& view);

// The same camera on a grid of block × block sub-pixels per pixel.
View subpixelView(const View& camera, int block);

// The sub-pixel block the renderer draws `render` with: k for Samples = k², k = round(√Samples) capped
// at 8, lowered until the sub-pixel image (the larger side of Resolution × k) fits `maxTextureSize`, the
// device's largest texture in texels a side. The one rule the renderer and its preflight estimate share.
int subpixelBlock(const RenderSettings& render, int maxTextureSize);

}  // namespace hairgen
