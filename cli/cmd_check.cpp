// hairgen check SETUP: read a job's configuration the way every stage will, and report what it found.
#include <iostream>

#include "cli/commands.h"
#include "cli/common.h"
#include "libcore/config/setup.h"
#include "libcore/io/hair_cache.h"
#include "libcore/io/info.h"
#include "libcore/render/custom_shaders.h"
#include "libcore/util/json.h"
#include "stages/preflight/estimate.h"
#include "stages/preflight/scene.h"
#include "stages/shade.h"

#include <tbb/task_arena.h>

namespace hairgen::cli {

namespace {

// What check reports of a Setup read as every stage reads it: its effective values, the fitted shapes and
// root flow, the warnings, and the memory and time of each stage of run (a shot's frames included), having
// refused what run would refuse.
nlohmann::ordered_json checkReport(const std::string& setup, const Config& config, const Scene& scene,
                                   const CommonOptions& common) {
  readCustomShaders(config.setup);  // a custom stage the render would refuse (too large for a compiler)
  // A coupe run could not read: read where the file lies (its checks, not a copy of its arrays).
  if (config.setup.load) readStrands(config.setup.loadFile.path, {}, ArrayStorage::kMapped);
  nlohmann::ordered_json report =
      describeSetup(setup, config, scene.wick ? &*scene.wick : nullptr, scene.head ? &*scene.head : nullptr);
  if (!config.setup.meshConversion.describe().empty())
    report["meshConversion"] = config.setup.meshConversion.describe();
  const std::vector<std::string> fitted = fittedShapeLines(config.collision);
  if (!fitted.empty()) report["fittedShapes"] = fitted;
  if (scene.wick && config.hairstyle.rootFlow.resolved && config.hairstyle.rootTilt > 0.0)  // to freeze it
    report["fittedRootFlow"] = fittedRootFlowLine(config.hairstyle);
  // Roots alone grow guides, but interpolate (and run) need a surface: what run refuses, said here.
  if (scene.wick && !config.setup.load && scene.wick->triangles.empty()) {
    const std::string why =
        "the wick has no faces, only points (roots): grow grows guides on them, but "
        "interpolate and run need a surface (a scalp mesh) and refuse it";
    report["warnings"].push_back(why);
    note(common, "warning: " + why);
  }
  if (scene.wick && !config.setup.load) {
    // What run would refuse, refused here; the time of every stage of run, a shot's frames included.
    const bool shade = wantsShade(config.visuality, config.render);
    const size_t threads = size_t(tbb::this_task_arena::max_concurrency());
    for (const WorkEstimate& e : estimateRun(config, *scene.wick, shade, true, threads))
      requireFits(e, common.force);
    nlohmann::ordered_json work = nlohmann::ordered_json::array();
    double seconds = 0.0;
    for (const WorkEstimate& e : estimateShot(config, *scene.wick, shade, true, threads)) {
      work.push_back({{"stage", e.stage}, {"bytes", e.bytes}, {"seconds", e.seconds}, {"detail", e.detail}});
      if (e.frames > 0) work.back()["frames"] = e.frames;
      seconds += e.seconds;
    }
    report["work"] = work;
    report["workSeconds"] = seconds;
    report["workThreads"] = threads;
  }
  return report;
}

}  // namespace

void registerCheck(CLI::App& app, int& exitCode) {
  struct Options {
    CommonOptions common;
    std::string setup;
    bool json = false;
    bool canonical = false;
  };
  auto options = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand(
      "check",
      "Validate a Setup and every file it names (configs, meshes); print the effective values and digest");
  cmd->add_option("SETUP", options->setup, "The Setup file")->required();
  cmd->add_flag("--json", options->json, "Print the report as JSON");
  cmd->add_flag("--canonical", options->canonical,
                "Print every effective value, one `Section.Key value` a line");
  addCommonFlags(*cmd, options->common, true);
  addStandaloneFlag(
      *cmd, "--keys",
      "Print the reference of every config key (Markdown, as docs/config-keys.md) and exit (no "
      "SETUP needed)",
      [options] { return runCommand("check", options->common, [] { std::cout << keyReference(); }); });
  cmd->callback([options, &exitCode] {
    exitCode = runCommand("check", options->common, [&] {
      Stats stats("check");
      // As every stage's --stats: the overrides, the config's digest and its seed at the top.
      Config config = loadStageConfig(options->setup, options->common, SetupUse::kCheck, stats);
      const Scene scene = readScene(options->common, config, true, true, stats);
      const nlohmann::ordered_json report = checkReport(options->setup, config, scene, options->common);
      stats.json()["report"] = report;
      if (options->canonical) {
        std::cout << config.canonicalText();
      } else if (options->json) {
        std::cout << jsonText(report) << "\n";
      } else {
        std::cout << formatSetupReport(report);
      }
      stats.write(options->common);
    });
  });
}

}  // namespace hairgen::cli
