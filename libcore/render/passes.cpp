#include "libcore/render/passes.h"

#include <algorithm>
#include <cmath>

#include <tbb/task_group.h>

#include "glsl/embedded_glsl.h"
#include "libcore/render/camera_fragments.h"
#include "libcore/render/compute_raster.h"
#include "libcore/render/light_maps.h"
#include "libcore/render/line_decimation.h"
#include "libcore/render/readback.h"
#include "libcore/render/shader_interface.h"
#include "libcore/util/stopwatch.h"

namespace hairgen {

namespace {

// How far from the hair the chords the shading pass draws may stray: 3/8 of a pixel of the image being
// drawn (a sub-pixel when Samples asks for them; a strand is drawn at least a pixel wide, so its chord's
// line still overlaps the curve's).
constexpr double kChordPixels = 0.375;

// The current context's largest texture, texels a side.
int maxTextureSize() {
  GLint size = 4096;
  glGetIntegerv(GL_MAX_TEXTURE_SIZE, &size);
  return int(size);
}

// The light's maps' size when the input leaves it to the renderer: a texel no larger than a pixel at the
// scene's centre (a texel there is its distance from the light over the light's focal length in
// texels, which grows with the map's size), between kMinDomResolution and the smaller of
// kMaxDomResolution and the device's largest texture.
int lightMapSize(const RenderInput& in, const BoundingSphere& sphere, const View& camera) {
  if (in.domResolution > 0) return in.domResolution;
  const int largest = std::min(maxTextureSize(), kMaxDomResolution);
  const double lightFocalPerTexel = lightView(in.settings, sphere, 1).focalPx;
  const double lightDistance = glm::length(sphere.centre - in.settings.lightPosition);
  const double cameraDistance = glm::length(sphere.centre - in.settings.cameraPosition);
  const double pixel = std::max(cameraDistance, 1e-6) / camera.focalPx;
  const double texels = std::ceil(std::max(lightDistance, 1e-6) / (lightFocalPerTexel * pixel));
  return int(std::clamp(texels, double(kMinDomResolution), double(largest)));
}

// Whether hairgen's rasteriser runs on the device (RenderInput::rasteriser): where it can, and the hair's
// projected points (16 bytes each) and the light's integer maps (16 bytes a texel) fit its storage
// buffers (the camera's fragments, which cannot be known before, fall back to the CPU themselves).
// `refused`: why not, where the device's compiler rejects one of the passes (computePassesFailure).
bool rasteriseOnDevice(const RenderInput& in, int lightSize, std::string& refused) {
  if (in.rasteriser == RenderInput::Rasteriser::kCpu) return false;
  if (in.rasteriser == RenderInput::Rasteriser::kAuto && softwareRasteriser()) return false;  // no probe
  const bool can = computeRasterAvailable();
  const bool fits = fitsDevice(in.hair->points.size() * sizeof(raster::Vertex)) &&
                    fitsDevice(size_t(lightSize) * size_t(lightSize) * sizeof(glm::uvec4));
  if (in.rasteriser == RenderInput::Rasteriser::kDevice && !(can && fits))
    renderFailure(can ? "the hair is too large for this device's storage buffers; use --rasteriser cpu"
                      : "this device cannot run hairgen's rasteriser (no GL_ARB_gpu_shader_int64); use "
                        "--rasteriser cpu");
  if (!(can && fits)) return false;
  refused = computePassesFailure(in.keptFragments);
  if (!refused.empty() && in.rasteriser == RenderInput::Rasteriser::kDevice)
    renderFailure("this device's compiler rejects hairgen's rasteriser (" + refused +
                  "); use --rasteriser cpu");
  return refused.empty();
}

// Lines where every strand is at most a pixel and a half wide (at the scene's nearest point) and
// there are no sub-pixels; ribbons otherwise.
bool drawsRibbons(const RenderSettings& r, const BoundingSphere& sphere, const View& camera, int block) {
  const double nearest = std::max(glm::length(sphere.centre - r.cameraPosition) - sphere.radius, 1e-3);
  return block > 1 || r.strandWidth * camera.focalPx / nearest > 1.5;
}

void setView(const Program& p, const View& v) {
  p.set("uView", glm::mat4(v.view));
  p.set("uProj", glm::mat4(v.proj));
}

void setHairWidth(const Program& p, const View& v, const RenderSettings& r) {
  p.set("uViewport", glm::vec2(v.width, v.height));
  p.set("uFocalPx", float(v.focalPx));
  p.set("uWidth", float(r.strandWidth));
  p.set("uOpacity", float(r.strandOpacity));
}

// The light's maps and the light, for the shadow function (glsl/shadow.glsl) of a shading program.
void setShadowUniforms(const Program& p, const Scene& scene) {
  const RenderSettings& r = scene.settings;
  p.set("uLightView", glm::mat4(scene.light.view));
  p.set("uLightProj", glm::mat4(scene.light.proj));
  p.set("uLayers", glm::vec4(r.layerSizes));
  p.set("uLightPosition", glm::vec3(r.lightPosition));
  p.set("uLightColor", glm::vec3(r.lightColor));
  p.set("uAmbient", float(r.ambientIntensity));
}

// A program that draws the hair as strips at the camera's sub-pixels (the shading and motion passes),
// in use with the camera, the strands' width and the screen door's dither.
void useForHairStrips(const Program& p, const Scene& scene, const RenderSettings& r) {
  p.use();
  setView(p, scene.subpixel);
  setHairWidth(p, scene.subpixel, r);
  p.set("uMinWidth", float(scene.block));
  p.set("uBlock", scene.block);
  p.set("uOrder", ditherOrder(scene.block));
}

// A program's stage: `custom` in place of hairgen's `own` when the Setup names one, with the same
// prelude either way.
StageSource stage(const char* own, const std::optional<CustomStage>& custom = std::nullopt,
                  const char* key = "", StagePrelude prelude = {}) {
  StageSource s;
  s.text = assembleStage(prelude, custom ? custom->text : std::string(own));
  s.custom = custom ? &*custom : nullptr;
  s.key = key;
  s.variant = prelude.ribbon ? "for ribbons" : "";
  return s;
}

// The strands' own tangents, or polylineTangents() in `computed` when they carry none: tangentsOf()
// would copy them (115 MB at 150,000 strands of 64 points). `computed` lives to the end of the
// expression that calls this.
const PointArray& tangentsFor(const Strands& s, PointArray&& computed = {}) {
  if (!s.tangents.empty()) return s.tangents;
  computed = polylineTangents(s);
  return computed;
}

}  // namespace

// hairgen's own hair shading stage compiled for one model, and for hair without colours
// (glsl/hair_fragment.glsl): what it does not read, the vertex stage does not write.
std::string hairShadingDefines(ShadingModel model, bool colored) {
  return "#define HAIR_MODEL " + std::to_string(static_cast<int>(model)) + "\n" +
         (colored ? "" : "#define HAIR_WHITE\n");
}

Programs::Programs(bool ribbons, int block, const CustomShaders& custom, bool motion, ShadingModel model,
                   bool colored, bool rasterised)
    : hairDepth(stage(glsl::kHairVertex, custom.hairVert, "HairVert"), stage(glsl::kDepthFragment),
                "hair depth"),
      headDepth(stage(glsl::kHeadVertex, custom.headVert, "HeadVert"), stage(glsl::kDepthFragment),
                "head depth"),
      opacity(stage(glsl::kHairVertex, custom.hairVert, "HairVert"), stage(glsl::kOpacityFragment),
              "deep opacity"),
      headShade(stage(glsl::kHeadVertex, custom.headVert, "HeadVert"),
                stage(glsl::kHeadFragment, custom.headFrag, "HeadFrag", {.shadowFunction = true}),
                "head shading"),
      resolve(stage(glsl::kFullscreenVertex), stage(glsl::kResolveFragment), "resolve") {
  const std::string defines = custom.hairFrag ? "" : hairShadingDefines(model, colored);
  if (rasterised) {
    // One texel of the atlas per fragment, each its own sample: the screen door compiled to nothing
    // (SINGLE_SAMPLE).
    hairAtlas.emplace(stage(glsl::kFullscreenVertex),
                      stage(glsl::kHairFragment, custom.hairFrag, "HairFrag",
                            {.shadowFunction = true,
                             .screenDoor = true,
                             .singleSample = true,
                             .defines = defines,
                             .atlas = true}),
                      "hair shading");
    blend.emplace(stage(glsl::kFullscreenVertex), stage(glsl::kBlendFragment), "blend");
  } else {
    hairShade.emplace(stage(glsl::kHairVertex, custom.hairVert, "HairVert", {.ribbon = ribbons}),
                      stage(glsl::kHairFragment, custom.hairFrag, "HairFrag",
                            {.ribbon = ribbons,
                             .shadowFunction = true,
                             .screenDoor = true,
                             .singleSample = block == 1,
                             .defines = defines}),
                      "hair shading");
  }
  if (!motion) return;
  hairMotion.emplace(stage(glsl::kHairVertex, std::nullopt, "", {.ribbon = ribbons, .motion = true}),
                     stage(glsl::kMotionFragment, std::nullopt, "",
                           {.ribbon = ribbons, .screenDoor = true, .singleSample = block == 1}),
                     "hair motion");
  headMotion.emplace(stage(glsl::kHeadVertex, std::nullopt, "", {.motion = true}),
                     stage(glsl::kMotionFragment), "head motion");
  motionResolve.emplace(stage(glsl::kFullscreenVertex), stage(glsl::kMotionResolveFragment),
                        "motion resolve");
}

// The light's maps (light_maps.h), the hair as the camera's rasteriser sees it (hair_raster.h: its
// fragments wait for the head's depth, the shading pass), and where OpenGL draws the camera's hair (a
// custom HairVert, the motion pass) the strands' drawing order and chords (line_decimation.h),
// computed on TBB's threads while the main thread, which holds the GL context, uploads the hair and
// compiles the programs.
//
// Order: only without sub-pixels, where the shading stage is tested for depth before it runs (the screen
// door's discard would defer the test); a different order could only change which of two fragments of
// exactly equal depth is kept.
//
// Chords: within kChordPixels of a pixel of the image, measured where the hair is nearest the eye (where
// those are smallest); the pass, whose cost is llvmpipe's vertex stage on one thread, draws a fraction of
// the vertices and the same picture to that. Not for a custom HairVert, which gets every point.
struct Scene::Preparation {
  std::vector<uint32_t> order, camera;
  bool cameraChords = false;
  std::unique_ptr<HairLightMaps> lightMaps;    // when hairgen's rasteriser draws them
  std::unique_ptr<raster::Bands> cameraBands;  // when it draws the camera's hair
  // The light's projected for the device, when the rasteriser runs there (Scene::onDevice).
  std::unique_ptr<raster::Projection> lightProjection;
  bool software = false;  // the device rasterises in software
  tbb::task_group work;

  // Whether the device draws a projection: on a software rasteriser only one within its loop budget
  // (compute_raster.h: withinLoopBudget), the CPU the rest. Any thread may ask (`software` is known).
  bool deviceDraws(const raster::Projection& p) const { return !software || withinLoopBudget(p); }

  Preparation(const Scene& scene, const RenderInput& in) {
    // A pixel's width in metres at the nearest of the scene: depth over focalPx on the view's axis, and
    // cos² of the angle smaller toward the corners of the view (a sideways offset at angle θ moves
    // focalPx·δ/(z cos² θ) pixels), so the smallest is at the corner's angle.
    auto nearestPixel = [&](const View& v) {
      const double depth =
          glm::length(scene.sphere.centre - glm::dvec3(glm::inverse(v.view)[3])) - scene.sphere.radius;
      const double tanX = 1.0 / v.proj[0][0], tanY = 1.0 / v.proj[1][1];  // the half-angles' tangents
      return depth / v.focalPx / (1.0 + tanX * tanX + tanY * tanY);
    };
    const double cameraPixel = nearestPixel(scene.subpixel);
    const bool openGlCamera = !scene.rasterised || scene.motion;
    cameraChords = openGlCamera && !in.shaders.hairVert && !scene.ribbons && cameraPixel > 0.0;
    const Strands& hair = *in.hair;
    const double cameraTolerance = kChordPixels * cameraPixel;
    const bool ordered = openGlCamera && scene.block == 1;
    const glm::dmat4 view = scene.camera.view;
    const bool lightByRasteriser = !in.shaders.hairVert && in.lightMaps != RenderInput::LightMaps::kGl;
    const View& lightView = scene.light;
    const RenderSettings& r = in.settings;
    const View& subpixelView = scene.subpixel;
    const bool cameraByRasteriser = scene.rasterised;
    const bool onDevice = scene.onDevice;
    software = onDevice && softwareRasteriser();
    // One after the other, each on every thread. For the CPU the light's projection is freed (into its
    // maps) before the camera's is made, in its storage. For the device the camera's is made by the
    // Scene once the light's is uploaded and let go (Scene::Scene), so one projection is held at a time.
    work.run([=, this, &hair, &lightView, &subpixelView, &r] {
      raster::Bands spent;
      if (lightByRasteriser && onDevice) {
        raster::Projection p = raster::project(hair, lightView, r.strandWidth);
        if (deviceDraws(p)) lightProjection = std::make_unique<raster::Projection>(std::move(p));
      }
      if (lightByRasteriser && !lightProjection)
        lightMaps = std::make_unique<HairLightMaps>(
            rasteriseLightMaps(hair, lightView, r.strandWidth, r.layerSizes, &spent));
      if (cameraByRasteriser && !onDevice)
        cameraBands = std::make_unique<raster::Bands>(
            raster::projectIntoBands(hair, subpixelView, r.strandWidth, std::move(spent)));
    });
    work.run([=, this, &hair] {
      if (ordered) order = frontToBack(hair, view);
      if (cameraChords) camera = decimatedLineStrips(hair, cameraTolerance, order);
    });
  }
  // Waits for the work when the Scene's constructor throws before it did (a task's own failure is then
  // moot: the constructor's is the one that goes on).
  ~Preparation() {
    try {
      work.wait();
    } catch (...) {
    }
  }
};

Scene::Scene(const RenderInput& in)
    : settings(in.settings),
      visuality(in.visuality),
      sphere(boundingSphere(*in.hair, in.head)),
      block(subpixelBlock(in.settings, maxTextureSize())),
      camera(cameraView(in.settings, sphere)),
      subpixel(subpixelView(camera, block)),
      light(lightView(in.settings, sphere, lightMapSize(in, sphere, camera))),
      ribbons(drawsRibbons(in.settings, sphere, camera, block)),
      motion(in.previous.has_value()),
      rasterised(!in.shaders.hairVert),
      kept(in.keptFragments),
      onDevice(rasteriseOnDevice(in, light.width, deviceRefused)),
      preparing(std::make_unique<Preparation>(*this, in)),
      hair(*in.hair, tangentsFor(*in.hair), motion ? in.previous->hair : nullptr, in.readInPlace),
      head(in.head && !in.head->triangles.empty()
               ? std::make_unique<HeadGeometry>(*in.head, motion ? in.previous->head : nullptr)
               : nullptr),
      programs(ribbons, block, in.shaders, motion, in.settings.shadingModel, !in.hair->colors.empty(),
               rasterised) {
  if (motion) {
    // The projection's x and y do not depend on the near and far planes, so the previous camera is
    // the Render Info camera on this frame's sphere.
    const View before = cameraView(in.previous->settings, sphere);
    previousViewProj = before.proj * before.view;
    viewProj = camera.proj * camera.view;
  }
  preparing->work.wait();
  if (!preparing->order.empty()) hair.drawInOrder(*in.hair, preparing->order);
  lightMaps = std::move(preparing->lightMaps);
  cameraBands = std::move(preparing->cameraBands);
  if (preparing->lightProjection) {
    lightOnDevice = std::make_unique<DeviceProjection>(*preparing->lightProjection, &timer, "light_upload");
    preparing->lightProjection.reset();
  }
  if (rasterised && onDevice) {
    raster::Projection p = raster::project(*in.hair, subpixel, in.settings.strandWidth);
    if (preparing->deviceDraws(p))
      cameraOnDevice = std::make_unique<DeviceProjection>(p, &timer, "camera_upload");
    else
      cameraBands = std::make_unique<raster::Bands>(raster::intoBands(std::move(p)));
  }
  if (preparing->cameraChords)
    cameraLines = std::make_unique<LineStrips>(preparing->camera, kCameraChunkVertices);
  preparing.reset();
  checkGl("setting up");
}

Scene::~Scene() = default;

void Scene::releaseLightMaps() {
  lightMaps.reset();
  lightOnDevice.reset();
}

void Scene::releaseCameraBands() {
  cameraBands.reset();
  cameraOnDevice.reset();
}

void Scene::releaseGeometry() {
  glBindVertexArray(0);
  hair.release();
  releaseLightMaps();
  releaseCameraBands();
  cameraLines.reset();
  head.reset();
}

LightDepth lightDepthPass(const Scene& scene) {
  const int n = scene.light.width;
  const float far[4] = {kBackgroundZ, kBackgroundZ, kBackgroundZ, kBackgroundZ};
  const float one = 1.0f;
  LightDepth depth{Texture(GL_R32F, n, n), Texture(GL_R32F, n, n), std::nullopt};
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glDisable(GL_CULL_FACE);
  {
    Framebuffer fb({&depth.head}, n, n, true);
    fb.bind();
    glClearBufferfv(GL_COLOR, 0, far);
    glClearBufferfv(GL_DEPTH, 0, &one);
    if (scene.head) {
      scene.programs.headDepth.use();
      setView(scene.programs.headDepth, scene.light);
      scene.head->draw();
    }
  }
  if (scene.lightOnDevice) {
    depth.opacity.emplace(GL_RGBA32F, n, n);
    const RenderSettings& r = scene.settings;
    computeLightMaps(*scene.lightOnDevice, r.layerSizes, r.strandOpacity, kBackgroundZ, depth.hairStart,
                     *depth.opacity, nullptr, &scene.timer);
  } else if (scene.lightMaps) {
    glTextureSubImage2D(depth.hairStart.id, 0, 0, 0, n, n, GL_RED, GL_FLOAT,
                        scene.lightMaps->startMetresInPlace(kBackgroundZ));
  } else {
    Framebuffer fb({&depth.hairStart}, n, n, true);
    fb.bind();
    glClearBufferfv(GL_COLOR, 0, far);
    glClearBufferfv(GL_DEPTH, 0, &one);
    const Program& p = scene.programs.hairDepth;
    p.use();
    setView(p, scene.light);
    setHairWidth(p, scene.light, scene.settings);
    scene.hair.drawLines(nullptr);
  }
  checkGl("the light's depth pass");
  return depth;
}

Texture deepOpacityPass(const Scene& scene, LightDepth& depth) {
  if (depth.opacity) {
    Texture drawn = std::move(*depth.opacity);
    depth.opacity.reset();
    return drawn;
  }
  const int n = scene.light.width;
  Texture opacity(GL_RGBA32F, n, n);
  if (scene.lightMaps) {
    glTextureSubImage2D(opacity.id, 0, 0, 0, n, n, GL_RGBA, GL_FLOAT,
                        scene.lightMaps->opacityInPlace(scene.settings.strandOpacity));
    checkGl("the deep opacity map's upload");
    return opacity;
  }
  Framebuffer fb({&opacity}, n, n, false);
  fb.bind();
  const float zero[4] = {0, 0, 0, 0};
  glClearBufferfv(GL_COLOR, 0, zero);
  glDisable(GL_DEPTH_TEST);
  glEnable(GL_BLEND);
  glBlendFunc(GL_ONE, GL_ONE);
  const Program& p = scene.programs.opacity;
  p.use();
  setView(p, scene.light);
  setHairWidth(p, scene.light, scene.settings);
  p.set("uLayers", glm::vec4(scene.settings.layerSizes));
  glBindImageTexture(0, depth.hairStart.id, 0, GL_FALSE, 0, GL_READ_ONLY, GL_R32F);
  scene.hair.drawLines(nullptr);
  glBindImageTexture(0, 0, 0, GL_FALSE, 0, GL_READ_ONLY, GL_R32F);
  glDisable(GL_BLEND);
  checkGl("the deep opacity pass");
  return opacity;
}

namespace {

// The hair's shading stage's uniforms, for OpenGL's strands and for the rasteriser's fragments alike.
void setHairShading(const Program& p, const Scene& scene) {
  const RenderSettings& r = scene.settings;
  setShadowUniforms(p, scene);
  p.set("uEye", glm::vec3(r.cameraPosition));
  p.set("uAmbientColor", glm::vec3(scene.visuality.ambientColor));
  p.set("uDiffuseColor", glm::vec3(scene.visuality.diffuseColor));
  p.set("uSpecularColor", glm::vec3(scene.visuality.specularColor));
  p.set("uGlossiness", float(scene.visuality.glossiness));
  p.set("uModel", static_cast<int>(r.shadingModel));
  p.set("uBlend", float(r.volumetricBlend));
  p.set("uHasColor", scene.hair.hasColors ? 1 : 0);
  p.set("uHasNormal", scene.hair.hasNormals ? 1 : 0);
}

// Texels per row of the atlas the kept fragments are shaded in.
constexpr int kAtlasWidth = 4096;

// The camera's kept fragments in the device's buffers, laid out as CameraFragments' (words, first,
// tail), `count` of them.
struct FragmentBuffers {
  GLuint words, first, tail;
  size_t count;
};

// The rasteriser's kept fragments shaded one texel each in an atlas by the hair's shading stage, then
// blended front to back over the head (`head`: what the head's drawing left) into the returned image.
ShadedImage blendHair(const Scene& scene, const FragmentBuffers& f, const ShadedImage& head) {
  const int w = scene.subpixel.width, h = scene.subpixel.height;
  const int maxSize = maxTextureSize();
  const int atlasWidth = std::min(kAtlasWidth, maxSize);
  const size_t rows = std::max<size_t>(1, (f.count + size_t(atlasWidth) - 1) / size_t(atlasWidth));
  if (rows > size_t(maxSize))
    renderFailure("the camera sees " + std::to_string(f.count) +
                  " hair fragments, more than this device's largest texture holds; lower Samples");
  Texture atlasColor(GL_RGBA16F, atlasWidth, int(rows)), atlasData(GL_RGBA16F, atlasWidth, int(rows));
  {
    Framebuffer fb({&atlasColor, &atlasData}, atlasWidth, int(rows), false);
    fb.bind();
    // A fragment a custom HairFrag discards leaves its texel as cleared: no light stopped.
    const float nothing[4] = {0.0f, 0.0f, 0.0f, 0.0f};
    glClearBufferfv(GL_COLOR, 0, nothing);
    glClearBufferfv(GL_COLOR, 1, nothing);
    glDisable(GL_DEPTH_TEST);
    scene.hair.draw(true, false);  // binds the hair's storage buffers
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 5, f.words);
    const Program& p = *scene.programs.hairAtlas;
    p.use();
    setHairShading(p, scene);
    p.set("hairgenHasColor", scene.hair.hasColors ? 1 : 0);
    p.set("hairgenHasNormal", scene.hair.hasNormals ? 1 : 0);
    p.set("hairgenOpacity", float(scene.settings.strandOpacity));
    p.set("uOpacity", float(scene.settings.strandOpacity));  // a HairFrag may read it, as on OpenGL's lines
    p.set("hairgenAtlasWidth", atlasWidth);
    p.set("hairgenAtlasRows", int(rows));
    p.set("hairgenFragmentCount", int(f.count));  // requireShadable: within the atlas
    glDrawArrays(GL_TRIANGLES, 0, 3);             // one triangle over the atlas
    checkGl("the hair's shading");
  }
  ShadedImage image{Texture(GL_RGBA16F, w, h), Texture(GL_RGBA32F, w, h), true};
  Framebuffer fb({&image.color, &image.data}, w, h, false);
  fb.bind();
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 6, f.first);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 7, f.tail);
  glBindTextureUnit(kUnitSubpixelColor, head.color.id);
  glBindTextureUnit(kUnitSubpixelData, head.data.id);
  glBindTextureUnit(kUnitAtlasColor, atlasColor.id);
  glBindTextureUnit(kUnitAtlasData, atlasData.id);
  const Program& p = *scene.programs.blend;
  p.use();
  p.set("uAtlasWidth", atlasWidth);
  p.set("uImageWidth", w);
  p.set("uOpacity", float(scene.settings.strandOpacity));
  glDrawArrays(GL_TRIANGLES, 0, 3);
  checkGl("the hair's blending");
  return image;
}

}  // namespace

ShadedImage shadingPass(Scene& scene, const LightDepth& depth, const Texture& opacity, size_t& fragments,
                        double& fragmentSeconds) {
  const RenderSettings& r = scene.settings;
  const int w = scene.subpixel.width, h = scene.subpixel.height;
  ShadedImage image{Texture(GL_RGBA16F, w, h), Texture(GL_RGBA32F, w, h), false};
  {
    Framebuffer fb({&image.color, &image.data}, w, h, true);
    fb.bind();
    // Premultiplied: what nothing covers is 0 in every channel; the background belongs to the preview.
    const float background[4] = {0.0f, 0.0f, 0.0f, 0.0f};
    const float nothing[4] = {kBackgroundZ, 0.0f, 1.0f, 0.0f};
    const float one = 1.0f;
    glClearBufferfv(GL_COLOR, 0, background);
    glClearBufferfv(GL_COLOR, 1, nothing);
    glClearBufferfv(GL_DEPTH, 0, &one);
    glEnable(GL_DEPTH_TEST);
    glBindTextureUnit(kUnitHairStart, depth.hairStart.id);
    glBindTextureUnit(kUnitHeadDepth, depth.head.id);
    glBindTextureUnit(kUnitOpacityMap, opacity.id);
    if (scene.head) {
      const Program& p = scene.programs.headShade;
      p.use();
      setView(p, scene.subpixel);
      setShadowUniforms(p, scene);
      p.set("uHeadColor", glm::vec3(r.headColor));
      scene.head->draw();
    }
    if (!scene.rasterised) {
      const Program& p = *scene.programs.hairShade;
      useForHairStrips(p, scene, r);
      setHairShading(p, scene);
      if (scene.ribbons)
        scene.hair.draw(true);
      else
        scene.hair.drawLines(scene.cameraLines.get());
    }
    checkGl("the shading pass");
  }
  if (!scene.rasterised) return image;
  glFinish();
  Stopwatch clock;
  // No more than blendHair's atlas holds (rows of atlasWidth texels, at most the largest texture's).
  const int maxSize = maxTextureSize();
  const uint64_t atlasTexels = uint64_t(std::min(kAtlasWidth, maxSize)) * uint64_t(maxSize);
  if (scene.cameraOnDevice) {
    // The head's depth is the data's R, read where it lies.
    const std::optional<DeviceFragments> f = computeCameraFragments(
        *scene.cameraOnDevice, scene.kept, scene.head ? &image.data : nullptr, 0, &scene.timer);
    glFinish();
    fragmentSeconds = clock.lap();
    if (f) {
      requireShadable(f->count, atlasTexels);
      scene.releaseCameraBands();  // the projection on the device, before the atlas is made
      fragments = f->count;
      return blendHair(scene, {f->words->id, f->first->id, f->tail->id, f->count}, image);
    }
  }
  // The hair the head hides is no fragment of the pixel: the rasteriser gets the head's depth.
  std::vector<float> headDepth;
  if (scene.head) {
    headDepth.resize(size_t(w) * size_t(h));
    glBindBuffer(GL_PIXEL_PACK_BUFFER, 0);  // into client memory, not a readback buffer
    glGetTextureImage(image.data.id, 0, GL_RED, GL_FLOAT, GLsizei(headDepth.size() * sizeof(float)),
                      headDepth.data());
    checkGl("reading the head's depth");
  }
  // On the CPU: where the rasteriser runs there, or its fragments did not fit the device's buffers (the
  // projection read back from the device: the hair itself may be gone).
  std::optional<raster::Bands> readBack;
  if (!scene.cameraBands) readBack.emplace(raster::intoBands(scene.cameraOnDevice->read(&scene.timer)));
  const raster::Bands& bands = scene.cameraBands ? *scene.cameraBands : *readBack;
  const CameraFragments f =
      cameraFragments(bands, scene.kept, headDepth.empty() ? nullptr : headDepth.data(), atlasTexels);
  headDepth = {};
  readBack.reset();
  scene.releaseCameraBands();
  fragments = f.count();
  fragmentSeconds += clock.lap();
  // Read in place where the hair is: the fragments outlive these buffers, whose deletion waits for
  // the draws that read them (Buffer::reset).
  const bool inPlace = scene.hair.readsStrandsInPlace();
  const Buffer words(f.words.data(), f.words.size() * sizeof(uint32_t), inPlace);
  const Buffer first(f.first.data(), f.first.size() * sizeof(uint32_t), inPlace);
  const Buffer tail(f.tail.data(), f.tail.size() * sizeof(uint32_t), inPlace);
  return blendHair(scene, {words.id, first.id, tail.id, f.count()}, image);
}

ShadedImage resolvePass(const Scene& scene, ShadedImage&& subpixels) {
  // One sample a pixel, blended: the resolve would copy the image as it is (its sums over one sample;
  // the blend writes Z below 3e38 and W 0, the resolve's own bounds), into a 1080p frame's 66 MB of
  // fresh textures with a pass, so it is read where it was drawn. OpenGL's own strands count their A
  // here.
  if (scene.block == 1 && subpixels.blended) return std::move(subpixels);
  const int w = scene.camera.width, h = scene.camera.height;
  ShadedImage image{Texture(GL_RGBA32F, w, h), Texture(GL_RGBA32F, w, h), true};
  Framebuffer fb({&image.color, &image.data}, w, h, false);
  fb.bind();
  glDisable(GL_DEPTH_TEST);
  const Program& p = scene.programs.resolve;
  p.use();
  p.set("uBlock", scene.block);
  p.set("uBlended", subpixels.blended ? 1 : 0);
  glBindTextureUnit(kUnitSubpixelColor, subpixels.color.id);
  glBindTextureUnit(kUnitSubpixelData, subpixels.data.id);
  glBindVertexArray(scene.hair.vao);  // core profile draws need a vertex array; the triangle reads none
  glDrawArrays(GL_TRIANGLES, 0, 3);
  checkGl("the resolve");
  return image;
}

Texture motionPass(const Scene& scene) {
  const RenderSettings& r = scene.settings;
  const int w = scene.subpixel.width, h = scene.subpixel.height;
  Texture motion(GL_RGBA32F, w, h);
  Framebuffer fb({&motion}, w, h, true);
  fb.bind();
  const float nothing[4] = {0.0f, 0.0f, 0.0f, 0.0f};
  const float one = 1.0f;
  glClearBufferfv(GL_COLOR, 0, nothing);
  glClearBufferfv(GL_DEPTH, 0, &one);
  glEnable(GL_DEPTH_TEST);
  const glm::vec2 imageSize(scene.camera.width, scene.camera.height);
  if (scene.head) {
    const Program& p = *scene.programs.headMotion;
    p.use();
    setView(p, scene.subpixel);
    p.set("uViewProj", glm::mat4(scene.viewProj));
    p.set("uPreviousViewProj", glm::mat4(scene.previousViewProj));
    p.set("uImageSize", imageSize);
    scene.head->draw();
  }
  // OpenGL's lines (or ribbons) at least a pixel wide, with the screen door at sub-pixels: the motion of
  // what is nearest in each sub-pixel, a footprint wider than the beauty's thin strands.
  const Program& p = *scene.programs.hairMotion;
  useForHairStrips(p, scene, r);
  p.set("uViewProj", glm::mat4(scene.viewProj));
  p.set("uPreviousViewProj", glm::mat4(scene.previousViewProj));
  p.set("uImageSize", imageSize);
  if (scene.ribbons)
    scene.hair.draw(true);
  else
    scene.hair.drawLines(scene.cameraLines.get());
  checkGl("the motion pass");
  return motion;
}

Texture motionResolvePass(const Scene& scene, const Texture& subpixels) {
  const int w = scene.camera.width, h = scene.camera.height;
  Texture motion(GL_RGBA32F, w, h);
  Framebuffer fb({&motion}, w, h, false);
  fb.bind();
  glDisable(GL_DEPTH_TEST);
  const Program& p = *scene.programs.motionResolve;
  p.use();
  p.set("uBlock", scene.block);
  glBindTextureUnit(kUnitSubpixelMotion, subpixels.id);
  glBindVertexArray(scene.hair.vao);
  glDrawArrays(GL_TRIANGLES, 0, 3);
  checkGl("the motion resolve");
  return motion;
}

void readBack(const ShadedImage& image, const Texture* motion, const LightDepth* depth,
              const Texture* opacity, RenderOutput& out) {
  Image& b = out.beauty;
  b.width = image.color.width;
  b.height = image.color.height;
  b.channels = {"R", "G", "B", "A", "Z", kChannelOpacity, kChannelShadow};
  if (motion) b.channels.insert(b.channels.end(), {kChannelMotionU, kChannelMotionV});
  b.planes.resize(b.channels.size());
  std::vector<PlaneRead> reads;
  for (int c = 0; c < 4; ++c) reads.push_back({&image.color, c, &b.planes[size_t(c)]});
  for (int c = 0; c < 3; ++c) reads.push_back({&image.data, c, &b.planes[size_t(4 + c)]});
  if (motion)
    for (int c = 0; c < 2; ++c) reads.push_back({motion, c, &b.planes[size_t(7 + c)]});
  if (depth && opacity) {
    Image& d = out.dom;
    d.width = d.height = depth->hairStart.width;
    d.channels = {"Z", kChannelDomLayers[0], kChannelDomLayers[1], kChannelDomLayers[2],
                  kChannelDomLayers[3]};
    d.planes.resize(5);
    reads.push_back({&depth->hairStart, 0, &d.planes[0]});
    for (int c = 0; c < 4; ++c) reads.push_back({opacity, c, &d.planes[size_t(1 + c)]});
  }
  readPlanes(reads);
  checkGl("reading the images back");
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
}

// Threshold ranks that spread each coverage level evenly: Bayer's matrices for powers of two, a
// magic-square order for 3, a sheared order otherwise.
std::vector<int> ditherOrder(int k) {
  std::vector<int> order(size_t(k) * k);
  if ((k & (k - 1)) == 0) {
    for (int y = 0; y < k; ++y)
      for (int x = 0; x < k; ++x) {
        int v = 0;
        for (int bit = k >> 1, weight = 1; bit > 0; bit >>= 1, weight <<= 2) {
          bool bx = x & bit, by = y & bit;
          v += weight * ((bx != by ? 2 : 0) + (by ? 1 : 0));
        }
        order[size_t(y) * k + x] = v;
      }
    // v was built least-significant level last; reverse the base-4 digits so the coarsest level leads.
    int levels = 0;
    for (int t = k; t > 1; t >>= 1) ++levels;
    for (int& v : order) {
      int r = 0;
      for (int l = 0; l < levels; ++l) r = r * 4 + ((v >> (2 * l)) & 3);
      v = r;
    }
  } else if (k == 3) {
    order = {0, 7, 3, 6, 5, 2, 4, 1, 8};
  } else {
    for (int y = 0; y < k; ++y)
      for (int x = 0; x < k; ++x) order[size_t(y) * k + x] = ((x + y * k) * (k + 1)) % (k * k);
  }
  return order;
}

}  // namespace hairgen
