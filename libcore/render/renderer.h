// The hair renderer (thesis §4.1.5-4.1.6, Appendix A for the method): per light three passes —
// depth from the light, a deep opacity map of 4 layers with additive blending, and the shading pass
// from the camera reading both — into framebuffer objects of a headless EGL context.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "libcore/config/params.h"
#include "libcore/model/image.h"
#include "libcore/model/mesh.h"
#include "libcore/model/strands.h"
#include "libcore/render/camera_fragments.h"
#include "libcore/render/custom_shaders.h"
#include "libcore/render/shader_interface.h"
#include "libcore/util/progress.h"

namespace hairgen {

class GlContext;

// The beauty image's channels (DESIGN §6): R G B A premultiplied (a pixel nothing covers is 0 in all
// four; A is the share of its light the hair and the head stop), Z, and the AOVs as layers a
// compositor sorts, each a single grey channel: OpenEXR names a layer's channels LAYER.CHANNEL and a
// grey channel Y, so Nuke shows them as the layers opacity and shadow.
inline constexpr const char* kChannelOpacity =
    "opacity.Y";  // the light the hair stops in front of the head, 0-1
inline constexpr const char* kChannelShadow = "shadow.Y";  // the light that arrives, 1 in the open
// With the previous frame (render --motion), Nuke's motion layer: how far what covers the pixel moved on
// the image since the previous frame, in pixels, u to the right and v up; 0 where nothing is drawn.
inline constexpr const char* kChannelMotionU = "motion.u";
inline constexpr const char* kChannelMotionV = "motion.v";

// The light's deep opacity maps (render --dom): beside Z, the layer dom's four channels, each the
// opacity accumulated in one depth layer (Layer Sizes), so a compositor lists them under one layer.
inline constexpr const char* kChannelDomLayers[4] = {"dom.layer1", "dom.layer2", "dom.layer3", "dom.layer4"};

// A compute pass of hairgen's rasteriser on the device, or a transfer between the host and the device,
// in one frame (device_timer.h): the device's time in a pass, the host's in a transfer (its wait for the
// device included), summed over its runs (a pass runs once a slab of rows, a prefix sum once a level).
struct DeviceTime {
  std::string name;      // a pass: after its shader (glsl/camera_keep.glsl: "camera_keep"); "camera_upload"
  double seconds = 0.0;  // s
  uint64_t bytes = 0;    // a transfer's
  int runs = 0;
};

struct RenderTimings {
  double upload = 0.0, lightDepth = 0.0, opacity = 0.0, shading = 0.0, motion = 0.0, readback = 0.0;  // s
  double fragments = 0.0;  // of shading: the camera's hair fragments found by hairgen's rasteriser, s
  // Where the rasteriser ran on the device: its passes and transfers, in the order each first ran.
  std::vector<DeviceTime> devicePasses, transfers;
};

struct RenderOutput {
  Image beauty;  // R G B A (premultiplied), Z, kChannelOpacity, kChannelShadow[, kChannelMotionU, V]
  Image dom;     // the light's view: Z (distance along the light's axis where hair begins), kChannelDomLayers
  // OpenEXR's worldToCamera and worldToNDC of the camera and of the light (views.h: openExrWorldToCamera,
  // openExrWorldToNdc), for column vectors.
  glm::dmat4 worldToCamera{1.0}, worldToNdc{1.0};
  glm::dmat4 lightWorldToCamera{1.0}, lightWorldToNdc{1.0};
  RenderTimings timings;
  int samples = 1;               // the samples used (Samples, clamped to what the device offers)
  bool hairReadInPlace = false;  // whether the device read the hair where it lay (RenderInput::readInPlace)
  // Who drew the light's hair maps (RenderInput::lightMaps): hairgen's rasteriser (on the device when
  // rasterisedOnDevice), or OpenGL's lines.
  bool lightMapsByRasteriser = false;
  bool rasterisedOnDevice =
      false;                  // whether hairgen's rasteriser ran on the device (RenderInput::rasteriser)
  std::string deviceRefused;  // why it ran on the CPU where `auto` would have put it on the device, or empty
  size_t hairFragments = 0;   // the camera's kept hair fragments (camera_fragments.h), at the sub-pixels
  std::string note;           // what the user should hear of the input (WorkEstimate::note), or empty
  RenderSettings settings;    // what was rendered: the input's, with the camera and light the render stage
                              // aimed when asked to frame the hair
};

// The frame before this one, for motion vectors: the same strands (as many points) and head (as many
// vertices) a frame earlier, and the camera they were seen with.
struct PreviousFrame {
  const Strands* hair = nullptr;
  const Mesh* head = nullptr;  // required when RenderInput has a head
  RenderSettings settings;     // its camera (CameraPosition, CameraTarget, CameraUp, FieldOfView)
};

struct RenderInput {
  const Strands* hair = nullptr;
  const Mesh* head = nullptr;  // may be null
  Visuality visuality;
  RenderSettings settings;
  CustomShaders shaders;
  // Texels per side of the light's maps; 0: as the image needs, so that no texel is larger than a pixel
  // where the camera sees the middle of the scene, from kMinDomResolution up to the device's largest
  // texture or kMaxDomResolution (passes.cpp).
  int domResolution = 0;
  bool keepDom = false;
  std::optional<PreviousFrame> previous;  // motion vectors in the beauty image when given
  Progress* progress = nullptr;           // advanced once per pass (renderPassCount of them)
  // Who draws the hair into the light's maps: hairgen's integer rasteriser (light_maps.h), the same
  // bits on every machine, for kAuto and kCpu; OpenGL's lines for kGl and always for a custom HairVert,
  // whose vertices only OpenGL can place.
  enum class LightMaps { kAuto, kCpu, kGl };
  LightMaps lightMaps = LightMaps::kAuto;
  // Where hairgen's rasteriser runs, for the light's maps and the camera's fragments alike: on the CPU's
  // threads (hair_raster.h), or as compute passes on the device (compute_raster.h), the same bits
  // either way. kAuto: on the device when it is a GPU that can (GL_ARB_gpu_shader_int64), on the CPU
  // under a software rasteriser (llvmpipe runs compute passes on the same cores, slower than the
  // CPU's code). kDevice where the device cannot throws renderFailure.
  enum class Rasteriser { kAuto, kCpu, kDevice };
  Rasteriser rasteriser = Rasteriser::kAuto;
  // Called once renderHair reads the hair (and the frame before's) no more, so the caller may free
  // it: after the upload when the device holds a copy (the passes then do not run with both held);
  // after the last pass that draws it when the device reads it in place (readInPlace).
  std::function<void()> uploaded;
  // Let the device read the hair's large arrays where they lie, where it can (GL_AMD_pinned_memory,
  // llvmpipe): no copy, no second coupe held while it is made. The same images either way.
  bool readInPlace = true;
  // The hair fragments blended per sub-pixel, nearest first (camera_fragments.h); those behind blend as
  // one layer. kReferenceFragments with Samples 64 is the converged reference (render --reference).
  int keptFragments = kKeptFragments;
};

// The passes renderHair reports to its Progress: upload, light depth, opacity, shading, (motion,)
// read-back.
inline size_t renderPassCount(bool motion) {
  return motion ? 6 : 5;
}

// The light's maps' size when RenderInput::domResolution leaves it to the renderer: at least
// kMinDomResolution texels, and at most kMaxDomResolution (4096² texels hold 44 bytes each between the
// rasteriser's integers and the textures: 0.7 GB).
inline constexpr int kMinDomResolution = 512, kMaxDomResolution = 4096;

// Renders with the current context of `gl`; with the previous frame, a motion pass and its resolve
// after the shading pass (drawing hairgen's own vertex stages, never custom ones). Deterministic for a given
// device and driver. A custom stage that does not compile or link throws InputError at the file and line the
// GLSL compiler names; anything else that fails throws Error (exit code 1).
RenderOutput renderHair(GlContext& gl, const RenderInput& input);

}  // namespace hairgen
