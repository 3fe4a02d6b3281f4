// The passes of one render (deep opacity maps, Yuksel & Keyser 2008, as the thesis uses them in
// §4.1.6), each a function over the GPU objects of a Scene, called in turn by renderHair:
//   1. lightDepthPass:  from the light, the distance to the head (an opaque occluder) and to where the
//                       hair begins;
//   2. deepOpacityPass: 4 layers from where the hair begins, each strand fragment adding its opacity to
//                       its layer and every layer behind it;
//   3. shadingPass:     from the camera on the sub-pixel grid, the head and the hair lit and shadowed
//                       through both maps: the head drawn by OpenGL, the hair's kept fragments from
//                       hairgen's rasteriser (camera_fragments.h) shaded one texel each in an atlas and
//                       blended front to back over it (a custom HairVert's hair: OpenGL's lines or
//                       ribbons, opaque samples with a screen door);
//   4. resolvePass:     each block of sub-pixels box-filtered to a pixel;
//   (with the previous frame) motionPass and motionResolvePass: the same sub-pixel grid, what is seen
//                       in each sub-pixel drawn again with its screen motion since the previous frame,
//                       then averaged over each block's covered sub-pixels;
//   5. readBack:        the images into RenderOutput's planes, rows top to bottom.
// Each pass sets the GL state it needs and throws renderFailure when OpenGL reports an error.
#pragma once

#include <memory>
#include <optional>
#include <string>

#include "libcore/render/device_timer.h"
#include "libcore/render/gl_resources.h"
#include "libcore/render/renderer.h"
#include "libcore/render/views.h"

namespace hairgen {

struct HairLightMaps;     // light_maps.h
struct DeviceProjection;  // compute_raster.h
namespace raster {
struct Bands;  // hair_raster.h
}

// The programs of one render: hairgen's stages (libcore/render/glsl/), or the Setup's custom ones in
// their place (HairVert in every program that draws hair, HeadVert in every one that draws the head).
// `block`: k, sub-pixels per pixel side; at 1 the screen door is compiled out of the fragment stages.
// hairgen's own hair shading stage is compiled for `model`, and for white hair unless `colored`.
// `rasterised`: the camera's hair comes from hairgen's rasteriser (hairAtlas and blend), else OpenGL
// draws it (hairShade).
struct Programs {
  Programs(bool ribbons, int block, const CustomShaders& custom, bool motion, ShadingModel model,
           bool colored, bool rasterised);
  Program hairDepth, headDepth, opacity, headShade, resolve;
  std::optional<Program> hairShade;                              // OpenGL's lines or ribbons
  std::optional<Program> hairAtlas, blend;                       // the rasteriser's fragments
  std::optional<Program> hairMotion, headMotion, motionResolve;  // with the previous frame
};

// What every pass reads: the settings, the views, the geometry on the GPU and the programs. Building
// it uploads the geometry and compiles the programs.
struct Scene {
  explicit Scene(const RenderInput& input);
  ~Scene();

  const RenderSettings& settings;
  const Visuality& visuality;
  BoundingSphere sphere;  // around the hair and the head
  int block;              // k: sub-pixels per pixel side (Samples = k², as far as the device allows)
  View camera, subpixel;  // the camera on pixels and on sub-pixels
  View light;             // domResolution texels per side
  bool ribbons;           // OpenGL draws the camera's hair as ribbons, not lines
  bool motion;            // the previous frame was given: motion vectors too
  bool rasterised;        // the camera's hair comes from hairgen's rasteriser (not a custom HairVert)
  int kept;               // the fragments kept per sub-pixel (RenderInput::keptFragments)
  // Why hairgen's rasteriser runs on the CPU where `auto` would have put it on the device: the device's
  // compiler rejects one of its passes (computePassesFailure); empty otherwise. Declared before
  // onDevice, whose initialiser writes it.
  std::string deviceRefused;
  bool onDevice;  // hairgen's rasteriser runs on the device (RenderInput::rasteriser)
  glm::dmat4 viewProj{1.0}, previousViewProj{1.0};  // world to clip: this frame's camera, the previous one's
  // The device's time in the rasteriser's compute passes and the host's in their transfers (read once the
  // frame is done: RenderTimings::devicePasses, transfers); the passes time themselves (mutable), which
  // changes nothing they draw.
  mutable DeviceTimer timer;
  // What the CPU prepares for drawing while the GL objects below are made (passes.cpp).
  struct Preparation;
  std::unique_ptr<Preparation> preparing;
  HairGeometry hair;
  // The hair as chords when OpenGL draws the camera's lines (null: every point; a custom HairVert
  // always gets every point, since what it does to them is its own).
  std::unique_ptr<LineStrips> cameraLines;
  // The light's hair maps from hairgen's rasteriser (light_maps.h); null when OpenGL draws them from
  // every point (a custom HairVert, RenderInput::lightMaps).
  std::unique_ptr<HairLightMaps> lightMaps;
  // The hair as the camera's rasteriser sees it at the sub-pixels (hair_raster.h), its fragments drawn
  // in the shading pass, once the head's depth is known; null when OpenGL draws the camera's hair.
  std::unique_ptr<raster::Bands> cameraBands;
  // The same on the device, where the rasteriser runs there (onDevice): the light's projection and the
  // camera's, uploaded.
  std::unique_ptr<DeviceProjection> lightOnDevice, cameraOnDevice;
  std::unique_ptr<HeadGeometry> head;  // null when there is no head to draw
  Programs programs;

  // Frees the geometry once the passes that draw it are done, so what follows (the readback, the
  // images' writing) does not run with the coupe still held: the light's maps after their upload, the
  // camera's bands once the shading pass has their fragments (before it shades them), all of it after
  // the last pass.
  void releaseLightMaps();
  void releaseCameraBands();
  void releaseGeometry();
};

// The light's depth maps, metres along its axis (kBackgroundZ where nothing was drawn).
struct LightDepth {
  Texture head;       // R32F: to the head
  Texture hairStart;  // R32F: to where the hair begins
  // The deep opacity map, when the device's rasteriser drew it with the depth (deepOpacityPass takes it).
  std::optional<Texture> opacity;
};

// An image the shading pass draws and the resolve averages.
struct ShadedImage {
  Texture color;  // R G B of what was drawn (0 where nothing was), A (with `blended`) as the data says
  Texture data;   // Z (metres along the camera's axis), hair opacity, shadow (the light arriving)
  bool blended;   // R G B premultiplied and A the blended opacity; else opaque samples (A unused)
};

LightDepth lightDepthPass(const Scene& scene);
// RGBA32F, one layer per channel, the light's map size.
Texture deepOpacityPass(const Scene& scene, LightDepth& depth);
// At sub-pixel resolution; `fragments`: how many hair fragments the rasteriser kept (0 when OpenGL drew
// the hair), `fragmentSeconds` the time it took to find them (the device's work waited for). Releases
// the camera's bands once their fragments are made.
ShadedImage shadingPass(Scene& scene, const LightDepth& depth, const Texture& opacity, size_t& fragments,
                        double& fragmentSeconds);
// At the image's resolution: a blended image of one sample a pixel is that image, as it is.
ShadedImage resolvePass(const Scene& scene, ShadedImage&& subpixels);
// At sub-pixel resolution, RGBA32F: motion u, v (pixels of the image), 1 where something was drawn.
Texture motionPass(const Scene& scene);
// At the image's resolution: u, v.
Texture motionResolvePass(const Scene& scene, const Texture& subpixels);
// Into `out.beauty` (with the motion layer when `motion` is passed), and `out.dom` when the light's
// maps are passed.
void readBack(const ShadedImage& image, const Texture* motion, const LightDepth* depth,
              const Texture* opacity, RenderOutput& out);

// Threshold ranks for a k×k block of the screen door (k ≤ 8), row by row.
std::vector<int> ditherOrder(int k);

}  // namespace hairgen
