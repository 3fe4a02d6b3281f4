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
#include "libcore/util/text.h"
#include "stages/render.h"

namespace hairgen::cli {
namespace {

namespace fs = std::filesystem;

void requireExtension(const std::string& file, const char* extension, const char* flag) {
  if (toLower(fs::path(file).extension().string()) != extension)
    throw InputError(std::string(flag) + " " + file + ": expected a " + extension + " file");
}

}  // namespace

RenderOutput renderStage(const CommonOptions& common, const Config& config, const Strands& hair,
                         const Mesh* head, const RenderOptions& options, Stats& stats) {
  Stopwatch clock;
  const CustomShaders shaders = readCustomShaders(config.setup);
  stats.add("read", clock.lap());
  GlContext gl;
  stats.time("device", clock.lap());
  note(common, "render: " + gl.renderer() + " through EGL " + gl.platform() + ", " +
                   std::to_string(hair.strandCount()) + " strands at " +
                   std::to_string(config.render.resolution.x) + "x" +
                   std::to_string(config.render.resolution.y));
  RenderOptions withForce = options;
  withForce.force = common.force;
  RenderOutput out = render(gl, hair, head, config.visuality, config.render, shaders, withForce);
  stats.time("upload", out.timings.upload);
  stats.time("lightDepth", out.timings.lightDepth);
  stats.time("opacity", out.timings.opacity);
  stats.time("shading", out.timings.shading);
  stats.time("readback", out.timings.readback);
  stats.counts()["strands"] = hair.strandCount();
  stats.counts()["points"] = hair.pointCount();
  stats.counts()["samples"] = out.samples;
  stats.json()["device"] = {
      {"platform", gl.platform()}, {"renderer", gl.renderer()}, {"version", gl.version()}};
  if (out.samples != config.render.samples)
    note(common, "render: the device offers " + std::to_string(out.samples) + " samples; Samples " +
                     std::to_string(config.render.samples) + " was asked for");
  return out;
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
    std::string setup, hair, output, dom, preview;
    UnitOptions units;
    double scale = 1.0;
    bool frame = false, listDevices = false;
  };
  auto options = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand(
      "render",
      "Render a coupe headless (EGL): Kajiya-Kay hair, Lambert head, deep opacity map shadows, to EXR");
  cmd->add_option("SETUP", options->setup, "The Setup file (Visuality and Render Info, the head)");
  cmd->add_option("--hair", options->hair,
                  "The coupe: .hair (also cyHair files made elsewhere), .gltf, .glb, .ply or .data");
  cmd->add_option("-o,--output", options->output,
                  "Image to write: .exr with R G B A (half, premultiplied), Z, opacity.Y, shadow.Y");
  cmd->add_option("--dom", options->dom,
                  "Also write the light's maps: Z where the hair begins and the 4 opacity layers")
      ->type_name("FILE.exr");
  cmd->add_option("--preview", options->preview, "Also write an sRGB preview, over Render Info's Background")
      ->type_name("FILE.png");
  addUnitFlags(*cmd, options->units, "the hair file");
  CLI::Option* scale = cmd->add_option("--scale", options->scale,
                                       "Multiply the hair's positions and widths: --units as a factor")
                           ->check(kFiniteNonNegative & CLI::PositiveNumber);
  scale->excludes(cmd->get_option("--units"));
  cmd->add_flag("--frame", options->frame, "Aim the camera and light at the hair and fit it in the view");
  cmd->add_flag("--list-devices", options->listDevices, "List the EGL devices and platforms found, and exit");
  addCommonFlags(*cmd, options->common, true);
  cmd->footer(exitCodeHelp());
  cmd->callback([options, &exitCode] {
    exitCode = runCommand("render", options->common, [&] {
      if (options->listDevices) {
        std::vector<GlDeviceInfo> devices = GlContext::probe();
        for (const GlDeviceInfo& d : devices)
          std::cout << d.platform << ": " << (d.opened ? "opens, " + d.name : "does not open: " + d.error)
                    << (d.platform == "device" ? "  [" + d.name + "]" : "") << "\n";
        if (devices.empty()) std::cout << "no EGL platform found\n";
        return;
      }
      if (options->setup.empty() || options->hair.empty() || options->output.empty())
        throw InputError("render needs SETUP, --hair FILE and -o IMAGE.exr (or --list-devices)");
      requireExtension(options->output, ".exr", "-o");
      if (!options->dom.empty()) requireExtension(options->dom, ".exr", "--dom");
      if (!options->preview.empty()) requireExtension(options->preview, ".png", "--preview");
      Stats stats("render");
      Stopwatch clock;
      Config config = loadStageConfig(options->setup, options->common, SetupUse::kRender, stats);
      const Strands hair = readStrands(options->hair);
      if (config.render.shadingModel == ShadingModel::kVolumetric && config.render.volumetricBlend > 0.0 &&
          hair.normals.empty())
        throw InputError({options->hair, 0},
                         "ShadingModel volumetric needs the coupe's volume normals, and this one has "
                         "none; run `hairgen shade SETUP --hair " +
                             options->hair + " -o shaded.hair` and render that");
      std::optional<Mesh> head;
      if (config.setup.headModel.given()) head = readObj(config.setup.headModel.path);
      stats.time("read", clock.lap());
      RenderOptions renderOptions;
      renderOptions.frame = options->frame;
      const UnitConversion conversion = unitConversion(options->units);
      renderOptions.zUp = conversion.upAxis == UpAxis::kZ;
      renderOptions.scale = conversion.metresPerUnit.value_or(options->scale);
      renderOptions.keepDom = !options->dom.empty();
      RenderOutput out =
          renderStage(options->common, config, hair, head ? &*head : nullptr, renderOptions, stats);
      clock.lap();
      // The image's config digest is that of the camera and light it was rendered with (--frame aims them).
      config.render = out.settings;
      writeRenderOutputs(config, out, options->output, options->dom, options->preview);
      stats.time("write", clock.lap());
      note(options->common,
           "render: wrote " + options->output + (options->preview.empty() ? "" : " and " + options->preview));
      stats.write(options->common);
    });
  });
}

}  // namespace hairgen::cli
