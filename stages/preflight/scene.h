// A real head in the scene (README, Real heads): collision shapes fitted to it (`Ellipsoid v k auto`,
// `Sphere v k auto`), a plausibility check of the wick, the head, the collision shapes and the camera
// before any work starts, and the automatic camera (`CameraPosition auto`).
#pragma once

#include <string>
#include <vector>

#include "libcore/config/params.h"
#include "libcore/model/mesh.h"
#include "libcore/model/strands.h"

namespace hairgen {

// Fits every `auto` shape of `collision` to the head's cranium (or to the wick when `head` is null):
// an axis-aligned ellipsoid, or a sphere, that the roots sit on (libcore/model/shape_fit.h). The shapes
// keep their envelope growth and penalty, and stay marked as fitted.
void fitCollision(Collision& collision, const Mesh& wick, const Mesh* head);

// `RootFlow away-from auto`: the point is the whorl of the head, where hair parts and flows away on
// every side: on the cranium fitted as fitCollision fits it, behind its top, at (0, 2, −1)/√5 of its
// semi-axes from its centre (hairgen's heads face +z). On the bundled head that is the default
// coupe's own point, (0, 0.14, −0.04), to 4 mm. Does nothing unless RootFlow asks for it; InputError
// when no head can be fitted (too few points, a flat patch).
glm::dvec3 headWhorl(const Mesh& wick, const Mesh* head);
void fitRootFlow(Hairstyle& style, const Mesh& wick, const Mesh* head);
// The Hairstyle Info line that freezes a fitted RootFlow ("RootFlow away-from x y z", to 0.1 mm).
std::string fittedRootFlowLine(const Hairstyle& style);

// The lines a Collision Info would need to freeze the fitted shapes: "Ellipsoid 0.02 10 x y z a b c 1 0 0
// 0 1 0 0 0 1", one per fitted shape.
std::vector<std::string> fittedShapeLines(const Collision& collision);

struct SceneFinding {
  bool refuse = false;  // implausible for a head: the stage stops (exit 2) unless --force
  std::string message;  // what is wrong and the likely cause, naming the key to change
};

// Plausible sizes for a head (metres): a scalp's area, a whole head's, and the diagonal of a wick that is
// only points. Real scalps measure 0.02-0.1 m², whole heads with a neck and shoulders up to 0.4 m².
inline constexpr double kMinWickArea = 0.002, kMaxWickArea = 0.6;
inline constexpr double kMinWickSpan = 0.05, kMaxWickSpan = 0.8;

// Judges the scene as every stage and `hairgen check` see it (meshes already in metres, y up, collision
// shapes fitted): a wick too large or too small for a scalp (with the MeshUnits that would make it
// one), a wick outside every collision shape, a wick or head far from the origin for its size, and the
// wick outside the camera's view (when the camera is not auto).
std::vector<SceneFinding> checkScene(const Config& config, const Mesh& wick, const Mesh* head);

// CameraPosition auto: looks at the centre of the hair's and the head's bounding sphere from the gallery's
// three-quarter view (front right, a little above), far enough for the sphere to fit the view, the light
// above and to the right of the camera at the same proportion as the bundled coupes'.
void frameScene(RenderSettings& render, const Strands& hair, const Mesh* head);

}  // namespace hairgen
