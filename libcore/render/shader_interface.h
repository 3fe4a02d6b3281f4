// What the renderer's C++ and its GLSL share, declared once here: the texture units of the light's maps
// and the sub-pixel images, the shadow biases, the shading models' numbers, and the text put in front of
// every shader stage (hairgen's own, from libcore/render/glsl/, and a Setup's custom ones). GLSL sees
// the names below as constants of the same spelling.
#pragma once

#include <string>

namespace hairgen {

// The texture units the passes bind their maps to; GLSL declares each sampler with
// `layout(binding = kUnit...)`, so no unit is set by hand.
enum TextureUnit : int {
  kUnitHairStart = 0,      // R32F, the light's view: distance along its axis to where the hair begins, metres
  kUnitHeadDepth = 1,      // R32F, the light's view: distance along its axis to the head, metres
  kUnitOpacityMap = 2,     // RGBA32F, the light's view: the 4 deep opacity layers
  kUnitSubpixelColor = 3,  // RGBA16F, the shading pass's sub-pixels: color and opacity
  kUnitSubpixelData = 4,   // RGBA32F, the shading pass's sub-pixels: Z, hair opacity, shadow
  kUnitSubpixelMotion = 5,  // RGBA32F, the motion pass's sub-pixels: motion u, v (pixels), covered
  kUnitAtlasColor = 6,      // RGBA16F, the camera's kept hair fragments shaded: color and opacity
  kUnitAtlasData = 7,       // RGBA16F, the same fragments: Z, hair opacity, shadow
};
inline constexpr int kTextureUnitCount = 8;

// The unit's name as C++ and GLSL spell it ("kUnitHairStart").
const char* name(TextureUnit unit);

// Shadow biases, metres. The light's maps have texels a few millimetres wide at the head, so a surface
// compared with the map it drew itself into would shadow itself.
// A strand must not shadow itself: hair looks its shadow up 1 mm nearer the light.
inline constexpr float kShadowBiasHair = 0.001f;
// The head must not shadow itself where it faces the light: it looks its shadow up 2 mm off its
// surface, along its normal.
inline constexpr float kShadowOffsetHead = 0.002f;
// A point is behind the head only when 3 mm farther from the light than the head's depth map says, so
// the scalp and the roots on it are not cut off by the map's resolution.
inline constexpr float kShadowBiasHeadDepth = 0.003f;

// Camera depth (Z) of a pixel where nothing was drawn, metres; the resolve counts a sub-pixel as covered
// where its Z is nearer.
inline constexpr float kBackgroundZ = 1.0e10f;

// The light that still arrives behind opaque hair or the head: the thesis maps opacity [0, 1] to a
// shadow factor [1, 0.25], so nothing in shadow is ever black.
inline constexpr float kShadowFloor = 0.25f;

// What goes in front of one shader stage's text.
struct StagePrelude {
  bool ribbon = false;          // `#define RIBBON`: the hair is drawn as ribbons in this program
  bool shadowFunction = false;  // lightArriving() (glsl/shadow.glsl): the shading fragment stages
  bool screenDoor = false;      // screenDoor() (glsl/screen_door.glsl) and `#define SCREEN_DOOR`: the
                                // hair's shading and motion fragment stages
  bool singleSample = false;    // `#define SINGLE_SAMPLE`: no sub-pixels (k = 1), so screenDoor() compiles
                                // to nothing and a stage that does not discard of its own keeps llvmpipe's
                                // early depth test (a stage that may discard is shaded before its test)
  bool motion = false;          // `#define MOTION`: hairgen's own vertex stages in the motion pass also
                                // write vMotion, the screen motion since the previous frame
  std::string defines = {};     // more `#define` lines, for hairgen's own stages only (HAIR_MODEL, ...)
  bool atlas = false;           // the hair's shading stage run on the shading atlas' texels
                                // (glsl/atlas_inputs.glsl): its `in` declarations of vWorld, vTangent,
                                // vColor, vNormal, vAlpha and vDepth become plain globals (their
                                // qualifiers blanked, so lines and columns stay the file's), which a
                                // main() hairgen puts after the stage sets before it calls the stage's
                                // own (renamed hairgenShade)
};

// The GLSL constants: `const int kShading<Name> = <value>;` for every ShadingModel (the name from
// name(ShadingModel) in camel case, e.g. kShadingKajiyaKay), every TextureUnit, the shadow biases, and
// how the camera's fragments are packed (camera_fragments.h).
std::string glslConstants();

// `#version 450 core`, RIBBON and MOTION where asked, glslConstants(), the functions asked for, then `#line
// 1`, so the compiler numbers the stage's own lines from 1; `body` follows.
std::string assembleStage(const StagePrelude& prelude, const std::string& body);

// The first error of a GLSL compiler's or linker's log, on one line: its line number (0 when the log
// names none) and what it says, without the log's own location prefix and "error:". Reads the logs of
// Mesa ("0:12(5): error: ..."), NVIDIA ("0(12) : error C1008: ...") and glslang-style drivers
// ("ERROR: 0:12: ..."); another line shape comes back whole, at line 0.
struct CompilerMessage {
  int line = 0;
  std::string text;
};
CompilerMessage firstCompilerError(const std::string& log);

}  // namespace hairgen
