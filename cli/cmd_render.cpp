// hairgen render SETUP --hair FILE -o image.exr: Kajiya-Kay hair with deep opacity map shadows,
// headless through EGL, to an EXR with AOVs; --dom and --preview write the light's maps and a PNG.
#include <cmath>
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

namespace hairgen::cli {
namespace {

namespace fs = std::filesystem;

void requireExtension(const std::string& file, const char* extension, const char* flag) {
  if (toLower(fs::path(file).extension().string()) != extension)
    throw InputError(std::string(flag) + " " + file + ": expected a " + extension + " file");
}

// Hair made elsewhere: z-up to y-up, and a scale to metres.
void conform(Strands& hair, const std::string& upAxis, double scale) {
  auto fix = [&](glm::vec3 v, bool position) {
    if (upAxis == "z") v = glm::vec3(v.x, v.z, -v.y);
    return position ? v * static_cast<float>(scale) : v;
  };
  for (glm::vec3& p : hair.points) p = fix(p, true);
  for (glm::vec3& t : hair.tangents) t = fix(t, false);
  for (glm::vec3& n : hair.normals) n = fix(n, false);
  for (float& t : hair.thickness) t *= static_cast<float>(scale);
  hair.defaultThickness *= static_cast<float>(scale);
}

// Keeps the camera's and the light's directions and distances in proportion, but aims them at the
// hair and backs the camera off until the bounding sphere fits the view.
void frameHair(RenderSettings& r, const Strands& hair) {
  if (hair.points.empty()) return;
  const Bounds box = bounds(hair.points);
  const glm::dvec3 lo(box.min), hi(box.max);
  const glm::dvec3 centre = (lo + hi) * 0.5;
  const double radius = std::max(glm::length(hi - lo) * 0.5, 1e-3);
  const double fov = glm::radians(r.fieldOfView) * std::min(1.0, double(r.resolution.x) / r.resolution.y);
  const double distance = radius / std::sin(0.5 * fov) * 1.05;
  glm::dvec3 view = r.cameraPosition - r.cameraTarget, toLight = r.lightPosition - r.cameraTarget;
  double lightRatio = glm::length(toLight) / std::max(glm::length(view), 1e-9);
  r.cameraTarget = centre;
  r.cameraPosition = centre + glm::normalize(view) * distance;
  r.lightPosition = centre + glm::normalize(toLight) * distance * lightRatio;
}

}  // namespace

RenderOutput renderStage(const CommonOptions& common, const Config& config, const Strands& hair,
                         const Mesh* head, bool keepDom, Stats& stats) {
  Stopwatch clock;
  GlContext gl;
  stats.time("device", clock.lap());
  note(common, "render: " + gl.renderer() + " through EGL " + gl.platform() + ", " +
                   std::to_string(hair.strandCount()) + " strands at " +
                   std::to_string(config.render.resolution.x) + "x" +
                   std::to_string(config.render.resolution.y));
  RenderInput input;
  input.hair = &hair;
  input.head = head;
  input.visuality = config.visuality;
  input.settings = config.render;
  input.domResolution = domResolutionFor(config.render.resolution);
  input.keepDom = keepDom;
  RenderOutput out = renderHair(gl, input);
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
  if (!preview.empty()) writePreview(preview, out.beauty);
}

void registerRender(CLI::App& app, int& exitCode) {
  struct Options {
    CommonOptions common;
    std::string setup, hair, output, dom, preview, upAxis = "y";
    double scale = 1.0;
    bool frame = false, listDevices = false;
  };
  auto options = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand(
      "render",
      "Render a coupe headless (EGL): Kajiya-Kay hair, Lambert head, deep opacity map shadows, to EXR");
  cmd->add_option("SETUP", options->setup, "The Setup file (Visuality and Render Info, the head)");
  cmd->add_option("--hair", options->hair,
                  "The coupe: .hair (also cyHair files made elsewhere), .gltf or .glb");
  cmd->add_option("-o,--output", options->output,
                  "Image to write: .exr with R G B A (half), Z, opacity, shadow");
  cmd->add_option("--dom", options->dom,
                  "Also write the light's maps: Z where the hair begins and the 4 opacity layers")
      ->type_name("FILE.exr");
  cmd->add_option("--preview", options->preview, "Also write a tone-mapped sRGB preview")
      ->type_name("FILE.png");
  cmd->add_option("--up-axis", options->upAxis,
                  "The hair file's up axis; z turns z-up hair to hairgen's y-up")
      ->check(CLI::IsMember({"y", "z"}));
  cmd->add_option("--scale", options->scale,
                  "Multiply the hair's positions and widths (e.g. 0.01 for centimetres)")
      ->check(CLI::PositiveNumber);
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
      Strands hair = readStrands(options->hair);
      if (config.render.shadingModel == ShadingModel::kVolumetric && config.render.volumetricBlend > 0.0 &&
          hair.normals.empty())
        throw InputError({options->hair, 0},
                         "ShadingModel volumetric needs the coupe's volume normals, and this one has "
                         "none; run `hairgen shade SETUP --hair " +
                             options->hair + " -o shaded.hair` and render that");
      conform(hair, options->upAxis, options->scale);
      std::optional<Mesh> head;
      if (config.setup.headModel.given()) head = readObj(config.setup.headModel.path);
      if (options->frame) frameHair(config.render, hair);
      stats.time("read", clock.lap());
      RenderOutput out =
          renderStage(options->common, config, hair, head ? &*head : nullptr, !options->dom.empty(), stats);
      clock.lap();
      writeRenderOutputs(config, out, options->output, options->dom, options->preview);
      stats.time("write", clock.lap());
      note(options->common,
           "render: wrote " + options->output + (options->preview.empty() ? "" : " and " + options->preview));
      stats.write(options->common);
    });
  });
}

}  // namespace hairgen::cli
