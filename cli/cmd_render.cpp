// hairgen render SETUP --hair FILE -o image.exr: Kajiya-Kay hair with deep opacity map shadows,
// headless through EGL, to an EXR with AOVs; --dom and --preview write the light's maps and a PNG.
#include <iostream>
#include <map>

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
  const bool mapped = hair.points.get_allocator().holdsMapping();
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
  const char* rasteriser = out.rasterisedOnDevice ? "device" : "cpu";
  stats.json()["device"]["lightMaps"] = out.lightMapsByRasteriser ? rasteriser : "opengl";
  stats.json()["device"]["rasteriser"] = rasteriser;
  if (!out.deviceRefused.empty()) {
    // Once a render (each frame of a sequence asks the context, which kept the answer).
    if (!stats.json()["device"].contains("deviceRefused"))
      note(common, "render: hairgen's rasteriser runs on the CPU, the same image: " + out.deviceRefused);
    stats.json()["device"]["deviceRefused"] = out.deviceRefused;
  }
  if (!out.note.empty()) {
    // Once a render: a sequence's frames are all in the same units.
    if (!stats.json().contains("note")) note(common, "render: " + out.note);
    stats.json()["note"] = out.note;
  }
  stats.counts()["hairFragments"] = out.hairFragments;
  stats.json()["device"]["hairFragmentSeconds"] = out.timings.fragments;
  stats.json()["device"]["hairReadInPlace"] = out.hairReadInPlace;
  stats.json()["device"]["hairMapped"] = mapped;
  // The rasteriser's passes on the device and its transfers, summed over a sequence's frames as the
  // phases' seconds are.
  auto addTimes = [&](const char* key, const std::vector<DeviceTime>& times, bool bytes) {
    nlohmann::ordered_json& all = stats.json()["device"][key];
    if (all.is_null()) all = nlohmann::ordered_json::object();
    for (const DeviceTime& t : times) {
      nlohmann::ordered_json& one = all[t.name];
      if (one.is_null())
        one = bytes ? nlohmann::ordered_json{{"seconds", 0.0}, {"bytes", 0}, {"runs", 0}}
                    : nlohmann::ordered_json{{"seconds", 0.0}, {"runs", 0}};
      one["seconds"] = one["seconds"].get<double>() + t.seconds;
      if (bytes) one["bytes"] = one["bytes"].get<uint64_t>() + t.bytes;
      one["runs"] = one["runs"].get<int>() + t.runs;
    }
  };
  addTimes("passes", out.timings.devicePasses, false);
  addTimes("transfers", out.timings.transfers, true);
  return out;
}

std::unique_ptr<GlContext> openDevice(const CommonOptions& common, const Config& config, Stats& stats,
                                      std::future<std::unique_ptr<GlContext>>* opening) {
  Stopwatch clock;
  std::unique_ptr<GlContext> device;
  if (opening) {
    device = opening->get();
    device->makeCurrent();
  } else {
    device = std::make_unique<GlContext>();
  }
  const GlContext& gl = *device;
  stats.add("device", clock.lap());
  const GlStartTimes& start = gl.startTimes();
  stats.json()["device"] = {{"platform", gl.platform()},
                            {"renderer", gl.renderer()},
                            {"version", gl.version()},
                            {"start",
                             {{"devices", start.devices},
                              {"display", start.display},
                              {"context", start.context},
                              {"background", opening != nullptr}}}};
  note(common, "render: " + gl.renderer() + " through EGL " + gl.platform() + " at " +
                   std::to_string(config.render.resolution.x) + "x" +
                   std::to_string(config.render.resolution.y));
  return device;
}

void writeRenderOutputs(const Config& config, const RenderOutput& out, const std::string& exr,
                        const std::string& dom, const std::string& preview, std::optional<int> frame) {
  requireMappingsWhole();  // nothing made from a mapped coupe's unreadable page is written
  ExrMetadata meta;
  if (frame) {
    meta.ints["hairgen:frame"] = *frame;
    meta.framesPerSecond = config.dynamics.frameRate;
  }
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
    domMeta.ints = meta.ints;
    domMeta.framesPerSecond = meta.framesPerSecond;
    domMeta.strings["hairgen:layerSizes"] =
        std::to_string(config.render.layerSizes.x) + " " + std::to_string(config.render.layerSizes.y) + " " +
        std::to_string(config.render.layerSizes.z) + " " + std::to_string(config.render.layerSizes.w);
    domMeta.camera = true;
    domMeta.worldToCamera = out.lightWorldToCamera;
    domMeta.worldToNdc = out.lightWorldToNdc;
    writeExr(dom, out.dom, domMeta);
  }
  if (!preview.empty()) writePreview(preview, out.beauty, config.render.background);
}

namespace {

struct RenderArgs {
  CommonOptions common;
  std::string setup, hair, output, dom, preview, frames, guides, rest;
  UnitOptions units;
  double scale = 1.0;
  std::vector<double> translate;
  bool frame = false, motion = false, reference = false;
  RenderInput::Rasteriser rasteriser = RenderInput::Rasteriser::kAuto;
  bool sequence() const { return !frames.empty(); }
  bool fromGuides() const { return !guides.empty(); }
  // A file of the command: with --frames, frame `f`'s file of its pattern.
  std::string file(const std::string& pattern, int f) const {
    return sequence() && !pattern.empty() ? framePath(pattern, f).string() : pattern;
  }
};

void addRenderFlags(CLI::App& cmd, RenderArgs& args) {
  cmd.add_option("SETUP", args.setup, "The Setup file (Visuality and Render Info, the head)")->required();
  cmd.add_option("--hair", args.hair,
                 "The coupe: .hair (also cyHair files made elsewhere), .gltf, .glb, .ply or .data")
      ->type_name("FILE");
  cmd.add_option("-o,--output", args.output,
                 "Image to write: .exr with R G B A (half, premultiplied), Z, opacity.Y, shadow.Y")
      ->type_name("FILE.exr")
      ->required();
  cmd.add_option("--dom", args.dom,
                 "Also write the light's maps: Z where the hair begins and the 4 opacity layers")
      ->type_name("FILE.exr");
  cmd.add_option("--preview", args.preview, "Also write an sRGB preview, over Render Info's Background")
      ->type_name("FILE.png");
  addUnitFlags(cmd, args.units, "the hair file");
  CLI::Option* scale =
      cmd.add_option("--scale", args.scale,
                     "Multiply the hair's positions and widths by FACTOR > 0: --units as a factor")
          ->type_name("FACTOR")
          ->check(kFiniteNonNegative & CLI::PositiveNumber);
  scale->excludes(cmd.get_option("--units"));
  cmd.add_option("--translate", args.translate,
                 "Move the hair by X Y Z metres (each within +-10 km) after --units/--up-axis/--scale, to "
                 "sit it on the "
                 "head")
      ->expected(3)
      ->type_name("X Y Z")
      ->check(CLI::Range(-1e4, 1e4));
  cmd.add_flag("--frame", args.frame, "Aim the camera and light at the hair and fit it in the view");
  cmd.add_flag("--reference", args.reference,
               "Render the converged reference: 64 samples a pixel, each blending every hair fragment it "
               "sees (slow; what Samples is measured against, docs/rendering.md)");
  cmd.add_option("--rasteriser", args.rasteriser,
                 "Where hairgen's hair rasteriser runs: auto (the GPU's compute shaders on a GPU, the CPU's "
                 "threads under llvmpipe), cpu or device; the same image either way (docs/rendering.md)")
      ->transform(CLI::CheckedTransformer(
          std::map<std::string, RenderInput::Rasteriser>{{"auto", RenderInput::Rasteriser::kAuto},
                                                         {"cpu", RenderInput::Rasteriser::kCpu},
                                                         {"device", RenderInput::Rasteriser::kDevice}},
          CLI::ignore_case))
      ->type_name("WHERE");
  cmd.add_option(
         "--frames", args.frames,
         "Render these frames of a sequence in one process, one device: --hair, -o, --dom and --preview "
         "are patterns with ####, and the head moves with the Setup's HeadKeys")
      ->type_name("A-B");
  cmd.add_flag("--motion", args.motion,
               "With --frames, motion vectors too: the layer motion.u, motion.v, pixels moved since the "
               "frame before (from the --hair pattern's previous frame while it is in the shot)");
  cmd.add_option(
         "--guides", args.guides,
         "With --frames, instead of --hair: a simulated sequence's guides (sim/guides.####.hair), each "
         "frame interpolated and, when the Setup shades, re-posed from --rest in memory, as `run` "
         "does: a farm's frame chunk writes no per-frame coupes")
      ->type_name("PATTERN")
      ->excludes("--hair")
      ->needs("--frames");
  cmd.add_option("--rest", args.rest,
                 "With --guides: the shaded rest coupe whose normals and colours each frame takes (`shade` "
                 "--rest); needed when the Setup shades")
      ->type_name("FILE")
      ->needs("--guides");
}

// What needs no Setup: something to render, and files of the kinds written.
void checkRenderArgs(const RenderArgs& args) {
  if (args.hair.empty() && !args.fromGuides())
    throw InputError("render needs --hair FILE (or --frames with --guides PATTERN): the coupe to render");
  requireExtension(args.output, ".exr", "-o");
  if (!args.dom.empty()) requireExtension(args.dom, ".exr", "--dom");
  if (!args.preview.empty()) requireExtension(args.preview, ".png", "--preview");
}

// The frames rendered (a single image: frame 0), their patterns checked; where it will write, before
// the work (a sequence's first frame's files).
FrameRange renderedFrames(const RenderArgs& args) {
  if (args.motion && !args.sequence())
    throw InputError("--motion needs --frames: motion vectors are the movement since the frame before");
  const FrameRange frames = args.sequence() ? parseFrameRange(args.frames, "--frames") : FrameRange{0, 0};
  if (args.sequence())
    for (const std::string* pattern : {&args.hair, &args.guides, &args.output, &args.dom, &args.preview})
      if (!pattern->empty() && !isFramePattern(*pattern))
        throw InputError(*pattern + ": with --frames, write #### where the frame number goes");
  for (const std::string* file : {&args.output, &args.dom, &args.preview})
    if (!file->empty()) requireWritableOutput(args.file(*file, frames.first));
  return frames;
}

// With --guides, the shaded rest coupe each frame takes its normals and colours from (`shade --rest`),
// when the Setup shades; empty otherwise.
Strands readShadedRest(const RenderArgs& args, bool shaded) {
  if (args.fromGuides() && shaded && args.rest.empty())
    throw InputError(
        "--guides: this Setup shades, so each frame takes its normals from the shaded rest "
        "coupe: name it with --rest shaded.hair");
  if (args.fromGuides() && !shaded && !args.rest.empty())
    throw InputError("--rest: this Setup does not shade; each frame is rendered as interpolated");
  return args.rest.empty() ? Strands{} : readStrands(args.rest);
}

// --units, --up-axis and --scale describe the hair file alone: the head is read as the Setup says
// (MeshUnits, MeshUpAxis), so foreign hair sits on the bundled head; a head in the hair's units is asked
// for with --set Setup.MeshUnits=U (docs/real-heads.md).
RenderOptions renderOptionsOf(const RenderArgs& args) {
  RenderOptions renderOptions;
  renderOptions.frame = args.frame;
  const UnitConversion conversion = unitConversion(args.units);
  renderOptions.zUp = conversion.upAxis == UpAxis::kZ;
  renderOptions.scale = conversion.metresPerUnit.value_or(args.scale);
  renderOptions.keepDom = !args.dom.empty();
  renderOptions.reference = args.reference;
  renderOptions.rasteriser = args.rasteriser;
  return renderOptions;
}

// A --hair file as the render stage takes it: with --translate, converted (--units, --up-axis, --scale)
// and moved here, since the move comes after the conversion.
Strands readHair(const RenderArgs& args, const RenderOptions& renderOptions, const std::string& file) {
  // Where the file's pages lie: the render is done with it before the command ends (hair_io.h).
  Strands h = readStrands(file, {}, ArrayStorage::kMapped);
  if (!args.translate.empty()) {
    conform(h, renderOptions.zUp, renderOptions.scale);
    const glm::vec3 offset(args.translate[0], args.translate[1], args.translate[2]);
    for (glm::vec3& p : h.points) p += offset;
  }
  return h;
}

// A frame's hair can be rendered: the same strands as the frame before (for motion vectors), and the
// volume normals a volumetric ShadingModel needs.
void checkFrameHair(const Config& config, const Strands& hair, const std::string& hairFile,
                    const FrameBefore& before, const std::string& hairFileBefore) {
  if (before.hair && !sameStrands(hair, *before.hair))
    throw InputError({hairFile, 0}, "has other strands than " + hairFileBefore +
                                        " (frames of a sequence have the same strands and points), so "
                                        "no motion vectors can be drawn between them");
  if (config.render.shadingModel == ShadingModel::kVolumetric && config.render.volumetricBlend > 0.0 &&
      hair.normals.empty())
    throw InputError({hairFile, 0},
                     "ShadingModel volumetric needs the coupe's volume normals, and this one "
                     "has none; run `hairgen shade SETUP --hair " +
                         hairFile + " -o shaded.hair` and render that");
}

// Renders the frames (one image without --frames) and writes each: its hair a coupe file, or with
// --guides the shot's frame from its guides (stages/shot.h, the stage `run` calls, so the image is
// run's). One device for every frame.
void renderFrames(const RenderArgs& args, const Config& config, const ShotInputs& shot, FrameRange frames,
                  Stats& stats, Stopwatch& clock, std::future<std::unique_ptr<GlContext>>& opening) {
  const bool sequence = args.sequence();
  const RenderOptions renderOptions = renderOptionsOf(args);
  // One context for every frame (its programs and buffers kept from frame to frame), opening in the
  // background while the inputs are read and taken once the first frame's hair has been read: bad
  // input is exit 2 on a machine without a device too, not 3.
  std::unique_ptr<GlContext> gl;
  // Motion vectors of frame f are the movement from frame f - 1 whenever that frame is in the shot
  // (Dynamics Info's Frames; without one, the frames rendered), so a range split across jobs gives
  // the same vectors as one job; the shot's first frame has nothing before it and moves by 0.
  const int shotStart = config.dynamics.given ? config.dynamics.firstFrame : frames.first;
  ShotMotion before;  // with --motion, the frame before
  std::string hairFileBefore;
  if (args.motion && !config.dynamics.given)
    note(args.common, "hairgen render: no Dynamics Info names the shot's first frame, so frame " +
                          std::to_string(frames.first) +
                          " is taken as the first and moves by 0; a range split into jobs gives other "
                          "vectors where it is split (name the shot's DynamicsInfo in the Setup)");
  // --translate moves the hair after its conversion, so the stage gets it converted and moved.
  RenderOptions frameOptions = renderOptions;
  if (!args.translate.empty()) frameOptions.zUp = false, frameOptions.scale = 1.0;
  // A frame's hair and head. In a sequence the head moves with its keys (Dynamics Info), as the hair's
  // roots did; a single image has the head at rest.
  const std::string& pattern = args.fromGuides() ? args.guides : args.hair;
  auto loadFrame = [&](int f, std::string& file) {
    file = args.file(pattern, f);
    if (args.fromGuides()) return shotFrame(shot, f, readStrands(file), file);
    return ShotFrame{readHair(args, renderOptions, file), sequence ? shotHead(shot, f) : std::nullopt};
  };
  // A sequence aims an auto camera (or --frame) at its shot's first frame, so the camera holds still
  // and a range split into jobs sees through the same camera; when that frame's file is gone, at the
  // range's first.
  std::optional<Strands> framing;
  if (sequence && (args.frame || config.render.cameraAuto)) {
    std::string file;
    framing =
        loadFrame(fs::is_regular_file(args.file(pattern, shotStart)) ? shotStart : frames.first, file).coupe;
    frameOptions.framing = &*framing;
  }
  if (args.motion && frames.first - 1 >= shotStart) before.keep(loadFrame(frames.first - 1, hairFileBefore));
  Progress progress("render", "frames", size_t(frames.count()), sequence && !args.common.quiet);
  // One image: its passes are the progress (a 1080p coupe spends seconds in each on llvmpipe).
  Progress passes("render", "passes", renderPassCount(args.motion), !sequence && !args.common.quiet);
  if (!sequence) frameOptions.progress = &passes;
  for (int f = frames.first; f <= frames.last; ++f) {
    std::string hairFile;
    ShotFrame frame = loadFrame(f, hairFile);
    Strands& hair = frame.coupe;
    if (args.motion && !before.started()) hairFileBefore = hairFile;  // no motion at the shot's start
    const FrameBefore frameBefore = args.motion ? before.before(frame) : FrameBefore{};
    checkFrameHair(config, hair, hairFile, frameBefore, hairFileBefore);
    stats.add("read", clock.lap());
    // Without motion vectors the frame's hair has no use once the render reads it no more: freed
    // then (after the upload where the device copies it, so the passes run without a second copy
    // of a 150,000-strand coupe's 230 MB).
    frameOptions.uploaded = nullptr;
    if (!args.motion) frameOptions.uploaded = [&hair] { hair = Strands{}; };
    if (!gl) gl = openDevice(args.common, config, stats, &opening);
    RenderOutput out = renderStage(args.common, config, *gl, hair,
                                   frame.head  ? &*frame.head
                                   : shot.head ? shot.head
                                               : nullptr,
                                   frameOptions, stats, args.motion ? &frameBefore : nullptr);
    clock.lap();
    // The image's config digest is the Setup's, as `run` and a farm plan write and expect it (an auto
    // camera is part of the Setup: the same inputs aim it the same way). --frame, which is not,
    // aims the camera and light itself: then the digest is that of the ones it rendered with.
    Config rendered = config;
    if (args.frame) rendered.render = out.settings;
    writeRenderOutputs(rendered, out, args.file(args.output, f), args.file(args.dom, f),
                       args.file(args.preview, f), sequence ? std::optional<int>(f) : std::nullopt);
    if (sequence) keepCommittedOutputs();  // a finished frame stays, whatever a later one does
    stats.add("write", clock.lap());
    if (args.motion) {
      hairFileBefore = hairFile;
      before.keep(std::move(frame));
    }
    progress.advance();
  }
  progress.finish();
  passes.finish();
}

// What was written: a sequence names its first and last frames' files, as run does.
std::string writtenFiles(const RenderArgs& args, FrameRange frames, const std::string& files) {
  return args.sequence() && frames.last > frames.first
             ? args.file(files, frames.first) + " to " + args.file(files, frames.last)
             : args.file(files, frames.last);
}

}  // namespace

void registerRender(CLI::App& app, int& exitCode) {
  auto options = std::make_shared<RenderArgs>();
  std::string models;  // from the one list the config reader takes
  for (ShadingModel model : kShadingModels) models += std::string(models.empty() ? "" : ", ") + name(model);
  CLI::App* cmd = app.add_subcommand(
      "render",
      "Render a coupe headless (EGL) to EXR: the hair lit by Render Info's ShadingModel (" + models +
          "), a Lambert head, deep opacity map shadows. With --frames, a sequence in one process: per-frame "
          "coupes (--hair PATTERN) or a simulated shot's guides (--guides PATTERN)");
  addRenderFlags(*cmd, *options);
  addCommonFlags(*cmd, options->common, true);
  addStandaloneFlag(*cmd, "--list-devices",
                    "List the EGL devices and platforms found, and exit (no SETUP needed)",
                    [options] { return runCommand("render", options->common, listDevices); });
  cmd->callback([options, &exitCode] {
    exitCode = runCommand("render", options->common, [&] {
      const RenderArgs& args = *options;
      checkRenderArgs(args);
      // The device starts (tens of milliseconds in a GPU's driver) while the Setup and the hair are read.
      std::future<std::unique_ptr<GlContext>> opening = GlContext::openInBackground();
      Stats stats("render");
      Stopwatch clock;
      Config config = loadStageConfig(args.setup, args.common,
                                      args.fromGuides() ? SetupUse::kRun : SetupUse::kRender, stats);
      const FrameRange frames = renderedFrames(args);
      Scene scene = readScene(args.common, config, args.fromGuides(), true, stats);
      const bool shaded = wantsShade(config.visuality, config.render);
      const Strands rest = readShadedRest(args, shaded);
      stats.time("read", clock.lap());
      const ShotInputs shot{&config,
                            scene.wick ? &*scene.wick : nullptr,
                            shaded ? &rest : nullptr,
                            scene.head ? &*scene.head : nullptr,
                            headMotionOf(config),
                            args.common.force};
      renderFrames(args, config, shot, frames, stats, clock, opening);
      note(args.common, "render: wrote " + writtenFiles(args, frames, args.output) +
                            (args.preview.empty() ? "" : " and " + writtenFiles(args, frames, args.preview)));
      stats.write(args.common);
    });
  });
}

}  // namespace hairgen::cli
