// hairgen render SETUP --hair FILE -o image.exr: Kajiya-Kay hair with deep opacity map shadows,
// headless through EGL, to an EXR with AOVs; --dom and --preview write the light's maps and a PNG.
#include <iostream>

#include "cli/commands.h"
#include "cli/common.h"
#include "libcore/config/setup.h"
#include "libcore/io/exr_io.h"
#include "libcore/io/hair_cache.h"
#include "libcore/io/obj_io.h"
#include "libcore/render/gl_context.h"
#include "libcore/util/error.h"
#include "libcore/util/file_util.h"
#include "libcore/util/frames.h"
#include "libcore/util/progress.h"
#include "libcore/util/text.h"
#include "stages/interpolate.h"
#include "stages/render.h"
#include "stages/shade.h"
#include "stages/shot.h"
#include "stages/simulate.h"

namespace hairgen::cli {
namespace {

namespace fs = std::filesystem;

void requireExtension(const std::string& file, const char* extension, const char* flag) {
  if (toLower(fs::path(file).extension().string()) != extension)
    throw InputError(std::string(flag) + " " + file + ": expected a " + extension + " file");
}

// render --list-devices: what each EGL platform answered; a farm's health check reads the exit code,
// 3 when nothing here can render.
void listDevices() {
  std::vector<GlDeviceInfo> devices = GlContext::probe();
  for (const GlDeviceInfo& d : devices)
    std::cout << d.platform << ": " << (d.opened ? "opens, " + d.name : "does not open: " + d.error)
              << (d.platform == "device" ? "  [" + d.name + "]" : "") << "\n";
  if (devices.empty()) std::cout << "no EGL platform found\n";
  if (std::none_of(devices.begin(), devices.end(), [](const GlDeviceInfo& d) { return d.opened; }))
    throw DeviceError("no EGL platform opens an OpenGL 4.5 core context (the list above)");
}

}  // namespace

RenderOutput renderStage(const CommonOptions& common, const Config& config, GlContext& gl,
                         const Strands& hair, const Mesh* head, const RenderOptions& options, Stats& stats,
                         const FrameBefore* before) {
  Stopwatch clock;
  const CustomShaders shaders = readCustomShaders(config.setup);
  stats.add("read", clock.lap());
  RenderOptions withForce = options;
  withForce.force = common.force;
  const size_t strands = hair.strandCount(), points = hair.pointCount();  // `uploaded` may free the hair
  RenderOutput out = render(gl, hair, head, config.visuality, config.render, shaders, withForce, before);
  stats.add("upload", out.timings.upload);
  stats.add("lightDepth", out.timings.lightDepth);
  stats.add("opacity", out.timings.opacity);
  stats.add("shading", out.timings.shading);
  if (before) stats.add("motion", out.timings.motion);
  stats.add("readback", out.timings.readback);
  stats.counts()["strands"] = strands;
  stats.counts()["points"] = points;
  stats.counts()["samples"] = out.samples;
  stats.json()["device"]["lightMaps"] = out.lightMapsOnCpu ? "cpu" : "opengl";
  stats.json()["device"]["hairReadInPlace"] = out.hairReadInPlace;
  return out;
}

std::unique_ptr<GlContext> openDevice(const CommonOptions& common, const Config& config, Stats& stats) {
  Stopwatch clock;
  auto device = std::make_unique<GlContext>();
  const GlContext& gl = *device;
  stats.add("device", clock.lap());
  stats.json()["device"] = {
      {"platform", gl.platform()}, {"renderer", gl.renderer()}, {"version", gl.version()}};
  note(common, "render: " + gl.renderer() + " through EGL " + gl.platform() + " at " +
                   std::to_string(config.render.resolution.x) + "x" +
                   std::to_string(config.render.resolution.y));
  return device;
}

void writeRenderOutputs(const Config& config, const RenderOutput& out, const std::string& exr,
                        const std::string& dom, const std::string& preview) {
  ExrMetadata meta;
  meta.strings["producer"] = "hairgen " HAIRGEN_VERSION;
  meta.strings["hairgen:configDigest"] = config.digest();
  meta.strings["hairgen:shadingModel"] = name(config.render.shadingModel);
  meta.strings["hairgen:backgroundZ"] = "1e10";
  meta.strings["hairgen:alpha"] = "premultiplied: over a background, R G B + (1 - A) x background";
  const glm::dvec3& bg = config.render.background;
  meta.strings["hairgen:previewBackground"] =
      formatReal(bg.x) + " " + formatReal(bg.y) + " " + formatReal(bg.z);
  meta.floats["hairgen:fieldOfView"] = static_cast<float>(config.render.fieldOfView);  // degrees, vertical
  meta.sizes["hairgen:resolution"] = config.render.resolution;
  meta.camera = true;
  meta.worldToCamera = out.worldToCamera;
  meta.worldToNdc = out.worldToNdc;
  writeExr(exr, out.beauty, meta);
  if (!dom.empty()) {
    ExrMetadata domMeta;
    domMeta.strings = meta.strings;
    domMeta.strings["hairgen:layerSizes"] =
        std::to_string(config.render.layerSizes.x) + " " + std::to_string(config.render.layerSizes.y) + " " +
        std::to_string(config.render.layerSizes.z) + " " + std::to_string(config.render.layerSizes.w);
    domMeta.camera = true;
    domMeta.worldToCamera = out.worldToLight;
    domMeta.worldToNdc = out.worldToLight;
    writeExr(dom, out.dom, domMeta);
  }
  if (!preview.empty()) writePreview(preview, out.beauty, config.render.background);
}

void registerRender(CLI::App& app, int& exitCode) {
  struct Options {
    CommonOptions common;
    std::string setup, hair, output, dom, preview, frames, guides, rest;
    UnitOptions units;
    double scale = 1.0;
    std::vector<double> translate;
    bool frame = false, motion = false;
  };
  auto options = std::make_shared<Options>();
  std::string models;  // from the one list the config reader takes
  for (ShadingModel model : kShadingModels) models += std::string(models.empty() ? "" : ", ") + name(model);
  CLI::App* cmd = app.add_subcommand(
      "render",
      "Render a coupe headless (EGL) to EXR: the hair lit by Render Info's ShadingModel (" + models +
          "), a Lambert head, deep opacity map shadows. With --frames, a sequence in one process: per-frame "
          "coupes (--hair PATTERN) or a simulated shot's guides (--guides PATTERN)");
  cmd->add_option("SETUP", options->setup, "The Setup file (Visuality and Render Info, the head)")
      ->required();
  cmd->add_option("--hair", options->hair,
                  "The coupe: .hair (also cyHair files made elsewhere), .gltf, .glb, .ply or .data")
      ->type_name("FILE");
  cmd->add_option("-o,--output", options->output,
                  "Image to write: .exr with R G B A (half, premultiplied), Z, opacity.Y, shadow.Y")
      ->type_name("FILE.exr")
      ->required();
  cmd->add_option("--dom", options->dom,
                  "Also write the light's maps: Z where the hair begins and the 4 opacity layers")
      ->type_name("FILE.exr");
  cmd->add_option("--preview", options->preview, "Also write an sRGB preview, over Render Info's Background")
      ->type_name("FILE.png");
  addUnitFlags(*cmd, options->units, "the hair file");
  CLI::Option* scale =
      cmd->add_option("--scale", options->scale,
                      "Multiply the hair's positions and widths by FACTOR > 0: --units as a factor")
          ->type_name("FACTOR")
          ->check(kFiniteNonNegative & CLI::PositiveNumber);
  scale->excludes(cmd->get_option("--units"));
  cmd->add_option("--translate", options->translate,
                  "Move the hair by X Y Z metres (each within +-10 km) after --units/--up-axis/--scale, to "
                  "sit it on the "
                  "head")
      ->expected(3)
      ->type_name("X Y Z")
      ->check(CLI::Range(-1e4, 1e4));
  cmd->add_flag("--frame", options->frame, "Aim the camera and light at the hair and fit it in the view");
  cmd->add_option(
         "--frames", options->frames,
         "Render these frames of a sequence in one process, one device: --hair, -o, --dom and --preview "
         "are patterns with ####, and the head moves with the Setup's HeadKeys")
      ->type_name("A-B");
  cmd->add_flag("--motion", options->motion,
                "With --frames, motion vectors too: the layer motion.u, motion.v, pixels moved since the "
                "frame before (from the --hair pattern's previous frame while it is in the shot)");
  cmd->add_option(
         "--guides", options->guides,
         "With --frames, instead of --hair: a simulated sequence's guides (sim/guides.####.hair), each "
         "frame interpolated and, when the Setup shades, re-posed from --rest in memory, as `run` "
         "does: a farm's frame chunk writes no per-frame coupes")
      ->type_name("PATTERN")
      ->excludes("--hair")
      ->needs("--frames");
  cmd->add_option("--rest", options->rest,
                  "With --guides: the shaded rest coupe whose normals and colours each frame takes (`shade` "
                  "--rest); needed when the Setup shades")
      ->type_name("FILE")
      ->needs("--guides");
  addCommonFlags(*cmd, options->common, true);
  addStandaloneFlag(*cmd, "--list-devices",
                    "List the EGL devices and platforms found, and exit (no SETUP needed)",
                    [options] { return runCommand("render", options->common, listDevices); });
  cmd->callback([options, &exitCode] {
    exitCode = runCommand("render", options->common, [&] {
      const bool fromGuides = !options->guides.empty();
      if (options->hair.empty() && !fromGuides)
        throw InputError("render needs --hair FILE (or --frames with --guides PATTERN): the coupe to render");
      requireExtension(options->output, ".exr", "-o");
      if (!options->dom.empty()) requireExtension(options->dom, ".exr", "--dom");
      if (!options->preview.empty()) requireExtension(options->preview, ".png", "--preview");
      Stats stats("render");
      Stopwatch clock;
      Config config = loadStageConfig(options->setup, options->common,
                                      fromGuides ? SetupUse::kRun : SetupUse::kRender, stats);
      const bool sequence = !options->frames.empty();
      if (options->motion && !sequence)
        throw InputError("--motion needs --frames: motion vectors are the movement since the frame before");
      const FrameRange frames = sequence ? parseFrameRange(options->frames, "--frames") : FrameRange{0, 0};
      if (sequence)
        for (const std::string* pattern :
             {&options->hair, &options->guides, &options->output, &options->dom, &options->preview})
          if (!pattern->empty() && !isFramePattern(*pattern))
            throw InputError(*pattern + ": with --frames, write #### where the frame number goes");
      auto frameFile = [&](const std::string& pattern, int f) {
        return sequence && !pattern.empty() ? framePath(pattern, f).string() : pattern;
      };
      // Where it will write, before the work (a sequence's first frame's files).
      for (const std::string* file : {&options->output, &options->dom, &options->preview})
        if (!file->empty()) requireWritableOutput(frameFile(*file, frames.first));
      Scene scene = readScene(options->common, config, fromGuides, true, stats);
      std::optional<Mesh> head = std::move(scene.head);
      const HeadMotion motion = headMotionOf(config);
      // From guides: what `run` does to a frame of a shot, in the same order, so the images are its.
      const bool shaded = wantsShade(config.visuality, config.render);
      if (fromGuides && shaded && options->rest.empty())
        throw InputError(
            "--guides: this Setup shades, so each frame takes its normals from the shaded rest "
            "coupe: name it with --rest shaded.hair");
      if (fromGuides && !shaded && !options->rest.empty())
        throw InputError("--rest: this Setup does not shade; each frame is rendered as interpolated");
      Strands rest;
      if (!options->rest.empty()) rest = readStrands(options->rest);
      // A frame of a shot from its guides, as `run` makes it (stages/shot.h).
      const ShotInputs shot{&config,
                            scene.wick ? &*scene.wick : nullptr,
                            shaded ? &rest : nullptr,
                            head ? &*head : nullptr,
                            motion,
                            options->common.force};
      stats.time("read", clock.lap());
      RenderOptions renderOptions;
      renderOptions.frame = options->frame;
      const UnitConversion conversion = unitConversion(options->units);
      renderOptions.zUp = conversion.upAxis == UpAxis::kZ;
      renderOptions.scale = conversion.metresPerUnit.value_or(options->scale);
      // --units, --up-axis and --scale describe the hair file alone: the head is read as the Setup says
      // (MeshUnits, MeshUpAxis), so foreign hair sits on the bundled head; a head in the hair's units
      // is asked for with --set Setup.MeshUnits=U (docs/real-heads.md).
      renderOptions.keepDom = !options->dom.empty();
      // One context for every frame, opened once the first frame's hair has been read: bad input is
      // exit 2 on a machine without a device too, not 3.
      std::unique_ptr<GlContext> gl;
      // Motion vectors of frame f are the movement from frame f - 1 whenever that frame is in the shot
      // (Dynamics Info's Frames; without one, the frames rendered), so a range split across jobs gives
      // the same vectors as one job; the shot's first frame has nothing before it and moves by 0.
      const int shotStart = config.dynamics.given ? config.dynamics.firstFrame : frames.first;
      ShotMotion before;  // with --motion, the frame before
      std::string hairFileBefore;
      if (options->motion && !config.dynamics.given)
        note(options->common,
             "hairgen render: no Dynamics Info names the shot's first frame, so frame " +
                 std::to_string(frames.first) +
                 " is taken as the first and moves by 0; a range split into jobs gives other "
                 "vectors where it is split (name the shot's DynamicsInfo in the Setup)");
      // --translate moves the hair after its conversion, so the stage gets it converted and moved.
      RenderOptions frameOptions = renderOptions;
      if (!options->translate.empty()) frameOptions.zUp = false, frameOptions.scale = 1.0;
      auto readHair = [&](const std::string& file) {
        Strands h = readStrands(file);
        if (!options->translate.empty()) {
          conform(h, renderOptions.zUp, renderOptions.scale);
          const glm::vec3 offset(options->translate[0], options->translate[1], options->translate[2]);
          for (glm::vec3& p : h.points) p += offset;
        }
        return h;
      };
      // A frame's hair: its coupe file, or with --guides the shot's frame from its guides, the stage
      // `run` calls, so the image is run's. In a sequence the head moves with its keys (Dynamics Info),
      // as the hair's roots did; a single image has the head at rest.
      const std::string& pattern = fromGuides ? options->guides : options->hair;
      auto loadFrame = [&](int f, std::string& file) {
        file = frameFile(pattern, f);
        if (fromGuides) return shotFrame(shot, f, readStrands(file), file);
        return ShotFrame{readHair(file), sequence ? shotHead(shot, f) : std::nullopt};
      };
      // A sequence aims an auto camera (or --frame) at its shot's first frame, so the camera holds still
      // and a range split into jobs sees through the same camera; when that frame's file is gone, at the
      // range's first.
      std::optional<Strands> framing;
      if (sequence && (options->frame || config.render.cameraAuto)) {
        std::string file;
        framing =
            loadFrame(fs::is_regular_file(frameFile(pattern, shotStart)) ? shotStart : frames.first, file)
                .coupe;
        frameOptions.framing = &*framing;
      }
      if (options->motion && frames.first - 1 >= shotStart)
        before.keep(loadFrame(frames.first - 1, hairFileBefore));
      Progress progress("render", "frames", size_t(frames.count()), sequence && !options->common.quiet);
      // One image: its passes are the progress (a 1080p coupe spends seconds in each on llvmpipe).
      Progress passes("render", "passes", renderPassCount(options->motion),
                      !sequence && !options->common.quiet);
      if (!sequence) frameOptions.progress = &passes;
      for (int f = frames.first; f <= frames.last; ++f) {
        std::string hairFile;
        ShotFrame frame = loadFrame(f, hairFile);
        Strands& hair = frame.coupe;
        if (options->motion && !before.started()) hairFileBefore = hairFile;  // no motion at the shot's start
        const FrameBefore frameBefore = options->motion ? before.before(frame) : FrameBefore{};
        if (frameBefore.hair && !sameStrands(hair, *frameBefore.hair))
          throw InputError({hairFile, 0}, "has other strands than " + hairFileBefore +
                                              " (frames of a sequence have the same strands and points), so "
                                              "no motion vectors can be drawn between them");
        if (config.render.shadingModel == ShadingModel::kVolumetric && config.render.volumetricBlend > 0.0 &&
            hair.normals.empty())
          throw InputError({hairFile, 0},
                           "ShadingModel volumetric needs the coupe's volume normals, and this one "
                           "has none; run `hairgen shade SETUP --hair " +
                               hairFile + " -o shaded.hair` and render that");
        stats.add("read", clock.lap());
        // Without motion vectors the frame's hair has no use once the render reads it no more: freed
        // then (after the upload where the device copies it, so the passes run without a second copy
        // of a 150,000-strand coupe's 230 MB).
        frameOptions.uploaded = nullptr;
        if (!options->motion) frameOptions.uploaded = [&hair] { hair = Strands{}; };
        if (!gl) gl = openDevice(options->common, config, stats);
        RenderOutput out = renderStage(options->common, config, *gl, hair,
                                       frame.head ? &*frame.head
                                       : head     ? &*head
                                                  : nullptr,
                                       frameOptions, stats, options->motion ? &frameBefore : nullptr);
        clock.lap();
        // The image's config digest is the Setup's, as `run` and a farm plan write and expect it (an auto
        // camera is part of the Setup: the same inputs aim it the same way). --frame, which is not,
        // aims the camera and light itself: then the digest is that of the ones it rendered with.
        Config rendered = config;
        if (options->frame) rendered.render = out.settings;
        writeRenderOutputs(rendered, out, frameFile(options->output, f), frameFile(options->dom, f),
                           frameFile(options->preview, f));
        if (sequence) keepCommittedOutputs();  // a finished frame stays, whatever a later one does
        stats.add("write", clock.lap());
        if (options->motion) {
          hairFileBefore = hairFile;
          before.keep(std::move(frame));
        }
        progress.advance();
      }
      progress.finish();
      passes.finish();
      // A sequence names its first and last frames' files, as run does.
      auto written = [&](const std::string& files) {
        return sequence && frames.last > frames.first
                   ? frameFile(files, frames.first) + " to " + frameFile(files, frames.last)
                   : frameFile(files, frames.last);
      };
      note(options->common, "render: wrote " + written(options->output) +
                                (options->preview.empty() ? "" : " and " + written(options->preview)));
      stats.write(options->common);
    });
  });
}

}  // namespace hairgen::cli
