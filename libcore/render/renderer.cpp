// Hair rendering with deep opacity maps (Yuksel & Keyser 2008, as the thesis uses them in §4.1.6).
//
// Strands are read by the vertex shader from storage buffers. A strand that is thinner than about a
// pixel everywhere in the view (real hair, unless the camera is very close) is drawn as a line strip;
// a wider one as a camera-facing ribbon StrandWidth wide (two vertices per point, a triangle strip).
// Either way a strand is at least one pixel wide with StrandOpacity as its opacity.
//
// Antialiasing is supersampling: Samples = k² renders the shading pass at k times the resolution
// (k = round(√Samples)), ribbons k sub-pixels wide, and a strand's opacity becomes screen-door
// coverage of each k×k block (an ordered threshold per sub-pixel: order-independent, no sorting, the
// same result on every run). A resolve pass box-filters each block: colour, hair opacity and shadow
// are averaged, Z is the nearest. (llvmpipe's multisampled lines cost four times as much.)
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
  out.lightMapsOnCpu = scene.lightMaps != nullptr;
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
  const ShadedImage image = resolvePass(scene, shadingPass(scene, depth, opacity));
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
  passDone();
  return out;
}

}  // namespace hairgen
