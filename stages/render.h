// The render stage: a coupe, the head and the Setup's looks to an image with AOVs (thesis §4.1.5-4.1.6;
// the passes are in libcore/render/renderer.h). Prints nothing, reads no files: the caller opens the
// device (GlContext) and reads the coupe, the head and any custom shader files.
//
// Custom shaders (README, Custom shaders). The Setup keys HairVert, HairFrag, HeadVert and HeadFrag
// name GLSL files that take the place of hairgen's own stage in that slot:
//   HairVert  the hair vertex stage of every pass that draws hair (the light's depth and deep opacity
//             passes, and the shading pass), so a shader that moves the strands moves their shadows;
//   HairFrag  the hair shading fragment stage;
//   HeadVert  the head vertex stage of every pass that draws the head (the light's depth pass and the
//             shading pass);
//   HeadFrag  the head shading fragment stage.
// hairgen's own stage for a slot is the reference example: libcore/render/glsl/hair_vertex.glsl,
// hair_fragment.glsl, head_vertex.glsl and head_fragment.glsl. A custom stage declares the inputs,
// outputs and uniforms it uses from those of hairgen's stage, with the same names, types and locations
// (an unused uniform may be left out; hairgen sets whatever the program has):
//   HairVert  lines: attributes aPosition, aTangent, aColor, aNormal at locations 0-3; ribbons
//             (RIBBON defined): storage buffers 0-3 of floats (points, tangents, colors, normals, 3 per
//             point), uHasColor, uHasNormal, and two vertices per point (gl_VertexID 2i, 2i + 1).
//             Uniforms uView, uProj, uViewport, uFocalPx, uWidth, uOpacity, uMinWidth. Writes
//             gl_Position and vWorld, vTangent, vColor, vNormal (vec3), vAlpha, vDepth (float: metres
//             along the view axis; the light's passes read it).
//   HairFrag  reads those outputs (where hairgen's rasteriser draws the hair, plain globals that it
//             sets: docs/rendering.md, Custom shaders, says what that asks of the file); uniforms uEye,
//             uLightPosition, uLightColor, uAmbient, uAmbientColor, uDiffuseColor, uSpecularColor,
//             uGlossiness, uModel, uBlend; writes oColor (location 0: RGB, and the strand's opacity: the
//             pixel's blend reads it where hairgen's rasteriser draws the hair; otherwise the image's A is
//             the sub-pixels something was drawn in) and oData (location 1: Z in metres, hair opacity 1, the
//             shadow, 0).
//   HeadVert  attributes aPosition, aNormal at locations 0-1; uniforms uView, uProj; writes gl_Position
//             and vWorld, vNormal, vDepth.
//   HeadFrag  reads those; uniforms uLightPosition, uLightColor, uAmbient, uHeadColor; writes oColor
//             (RGB, 1) and oData (Z, hair opacity 0, the shadow, 0).
// In front of the file hairgen puts `#version 450 core`, `#define RIBBON` when the program draws
// strands as ribbons, `#define SINGLE_SAMPLE` when there are no sub-pixels (Samples 1), the constants
// kShading<Model> (kShadingKajiyaKay, kShadingThesis, kShadingAnjyo, kShadingVolumetric: uModel's values),
// kUnit<Map> (texture units) and kShadowBiasHair, kShadowOffsetHead, kShadowBiasHeadDepth (metres), and in a
// fragment stage the shadow function `float lightArriving(vec3 world, float bias)` (1 in the open, down to
// 0.25; libcore/render/glsl/ shadow.glsl) and for HairFrag `void screenDoor(float alpha)` (supersampling's
// coverage; call it first). Then `#line 1`, so the compiler's line numbers are the file's. The file has no
// #version line. A file that fails to compile or link is an InputError (exit 2) whose one line names the file
// and the compiler's line: "hairfrag.glsl:12: 'foo' : undeclared identifier (compiling HairFrag, named at
// setup.txt:9)".
#pragma once

#include <functional>
#include <optional>
#include <string>

#include "libcore/config/params.h"
#include "libcore/model/mesh.h"
#include "libcore/model/strands.h"
#include "libcore/render/gl_context.h"
#include "libcore/render/renderer.h"

namespace hairgen {

// What the render stage does beyond Render Info.
struct RenderOptions {
  bool frame = false;     // aim the camera and the light at the hair and back the camera off until it fits
  bool zUp = false;       // the hair is z-up (made elsewhere): turned to hairgen's y-up
  double scale = 1.0;     // multiplies the hair's positions and widths, to metres (0.01 for centimetres)
  bool keepDom = false;   // return the light's maps in RenderOutput::dom
  int domResolution = 0;  // texels per side of the light's maps; 0: as the image needs (RenderInput)
  RenderInput::LightMaps lightMaps = RenderInput::LightMaps::kAuto;     // who draws them (RenderInput)
  RenderInput::Rasteriser rasteriser = RenderInput::Rasteriser::kAuto;  // where it runs (RenderInput)
  bool force = false;  // render work estimated to take absurdly long (never work that cannot fit)
  // The converged reference: Samples 64 (as far as the device allows) and kReferenceFragments per
  // sub-pixel, the ground truth the Setup's Samples are measured against (docs/rendering.md).
  bool reference = false;
  // The hair the camera is aimed at (--frame, CameraPosition auto), as read; null: the hair rendered.
  // A sequence names its shot's first frame, so the camera holds still over the shot.
  const Strands* framing = nullptr;
  Progress* progress = nullptr;  // advanced once per pass (renderPassCount)
  // Called once render() reads the hair no more (RenderInput::uploaded: after the upload when the
  // device copies it, after the last pass when it reads it in place): a caller that has no more use for
  // it may free it then.
  std::function<void()> uploaded;
};

// Hair made elsewhere, to hairgen's conventions: z-up turned to y-up (x, y, z) → (x, z, −y), then
// positions and widths scaled by `scale`.
void conform(Strands& hair, bool zUp, double scale);

// Keeps the camera's and the light's directions and distances from the target in proportion, but aims
// them at the centre of the hair's bounding sphere and backs the camera off until the sphere fits the
// view (5% spare). No hair: `render` unchanged.
void frameHair(RenderSettings& render, const Strands& hair);

// The frame before the one rendered, for motion vectors: its hair as read (conformed and framed as this
// frame's is) and its head as posed (null when there is no head).
struct FrameBefore {
  const Strands* hair = nullptr;
  const Mesh* head = nullptr;
};

// Whether `a` and `b` are the same strands (as many, each with as many points), as every frame of a
// sequence is, so a point of one is the same point of the other.
bool sameStrands(const Strands& a, const Strands& b);

// Renders `hair` (and `head`, which may be null) with the current context of `gl`: conformed, framed
// when asked, with the Setup's custom shaders in place of hairgen's stages; with the frame before
// (same strands, same head), the motion layer too. Throws InputError for a custom shader that does not
// compile or link, or for motion vectors asked of a custom HairVert or HeadVert (they move what the
// motion pass cannot follow); Error (exit 1) when the device fails.
RenderOutput render(GlContext& gl, const Strands& hair, const Mesh* head, const Visuality& visuality,
                    const RenderSettings& settings, const CustomShaders& shaders,
                    const RenderOptions& options, const FrameBefore* before = nullptr);

}  // namespace hairgen
