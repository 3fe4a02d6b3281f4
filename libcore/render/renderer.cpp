// Hair rendering with deep opacity maps (Yuksel & Keyser 2008, as the thesis uses them in §4.1.6).
//
// The hair is drawn by hairgen's own integer rasteriser (hair_raster.h) for the light's maps and for
// the camera (camera_fragments.h): at its true width, each pixel's nearest fragments kept in depth
// order. OpenGL draws the head, shades every kept fragment with the hair's fragment stage, and blends
// each pixel's fragments front to back over the head. A custom HairVert, whose vertices only OpenGL can
// place, gets OpenGL's lines (or ribbons where a strand is wider than about a pixel and a half) at least
// a pixel wide instead, opaque samples with a screen door.
//
// Antialiasing: hair's coverage is exact at any Samples; Samples = k² renders the shading pass at k
// times the resolution (k = round(√Samples)) for the head's edges and the order of strands within a
// pixel, and a resolve pass box-filters each block: colour, A, hair opacity and shadow are averaged,
// Z is the nearest.
//
// The pieces: gl_resources.h (the GL objects), views.h (camera and light), shader_interface.h (what
// C++ and GLSL share), glsl/ (the stages), passes.h (one function per pass).
#include "libcore/render/renderer.h"

#include "libcore/render/passes.h"
#include "libcore/render/views.h"
#include "libcore/util/stopwatch.h"

namespace hairgen {

namespace {

// A pass's time: the GPU's queue drained first, so the time is the pass's and not the next one's.
double seconds(Stopwatch& clock) {
  glFinish();
  return clock.lap();
}

}  // namespace

RenderOutput renderHair(GlContext&, const RenderInput& in) {
  RenderOutput out;
  Stopwatch clock;
  clearGlErrors();
  Scene scene(in);
  out.samples = scene.block * scene.block;
  out.settings = in.settings;
  out.worldToCamera = openExrWorldToCamera(scene.camera);
  out.worldToNdc = openExrWorldToNdc(scene.camera);
  out.lightWorldToCamera = openExrWorldToCamera(scene.light);
  out.lightWorldToNdc = openExrWorldToNdc(scene.light);
  out.timings.upload = seconds(clock);
  out.hairReadInPlace = scene.hair.readsStrandsInPlace();
  out.lightMapsByRasteriser = scene.lightMaps || scene.lightOnDevice;
  out.rasterisedOnDevice = scene.lightOnDevice || scene.cameraOnDevice;
  out.deviceRefused = scene.deviceRefused;
  if (in.uploaded && !out.hairReadInPlace) in.uploaded();
  auto passDone = [&] {
    if (in.progress) in.progress->advance();
  };
  passDone();

  LightDepth depth = lightDepthPass(scene);
  out.timings.lightDepth = seconds(clock);
  passDone();
  const Texture opacity = deepOpacityPass(scene, depth);
  scene.releaseLightMaps();
  out.timings.opacity = seconds(clock);
  passDone();
  const ShadedImage image =
      resolvePass(scene, shadingPass(scene, depth, opacity, out.hairFragments, out.timings.fragments));
  out.timings.shading = seconds(clock);
  passDone();
  std::optional<Texture> motion;
  if (scene.motion) {
    motion.emplace(motionResolvePass(scene, motionPass(scene)));
    out.timings.motion = seconds(clock);
    passDone();
  }
  scene.releaseGeometry();
  if (in.uploaded && out.hairReadInPlace) in.uploaded();
  readBack(image, motion ? &*motion : nullptr, in.keepDom ? &depth : nullptr, in.keepDom ? &opacity : nullptr,
           out);
  out.timings.readback = seconds(clock);
  out.timings.devicePasses = scene.timer.passes();
  out.timings.transfers = scene.timer.transfers();
  passDone();
  return out;
}

}  // namespace hairgen
