// hairgen grow SETUP -o guides.{hair,gltf,glb}: one Super-Helix guide per wick vertex.
#include "cli/commands.h"
#include "cli/common.h"
#include "libcore/file_util.h"
#include "libcore/hair_cache.h"
#include "libcore/obj_io.h"
#include "libcore/setup.h"
#include "stages/grow.h"

namespace hairgen::cli {

void registerGrow(CLI::App& app, int& exitCode) {
  struct Options {
    CommonOptions common;
    std::string setup, output, diagnostics;
  };
  auto options = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand(
      "grow", "Grow one Super-Helix guide per wick vertex at its static equilibrium (elasticity, gravity, collisions)");
  cmd->add_option("SETUP", options->setup, "The Setup file")->required();
  cmd->add_option("-o,--output", options->output, "Guides to write: .hair, .gltf or .glb (written atomically)")->required();
  cmd->add_option("--diagnostics", options->diagnostics,
                  "Write per guide: follicle, generalised coordinates, energy terms at start and end, stages, "
                  "evaluations, why it stopped")
      ->type_name("FILE.json");
  addCommonFlags(*cmd, options->common, true);
  cmd->footer(exitCodeHelp());
  cmd->callback([options, &exitCode] {
    exitCode = runCommand("grow", options->common, [&] {
      Stats stats("grow");
      hairFormatOf(options->output);
      std::vector<Override> overrides = parseOverrides(options->common);
      stats.setOverrides(overrides);
      auto t0 = std::chrono::steady_clock::now();
      Config config = loadConfig(options->setup, overrides, SetupUse::kGrow);
      Mesh wick = readObj(config.setup.wickModel.path);
      auto t1 = std::chrono::steady_clock::now();
      note(options->common, "grow: " + std::to_string(wick.vertexCount()) + " guides from " +
                                config.setup.wickModel.path.string());
      Progress progress("grow", "guides", wick.vertexCount(), !options->common.quiet);
      GrowResult result = grow(wick, config.hairstyle, config.collision, GrowOptions{config.digest(), &progress});
      auto t2 = std::chrono::steady_clock::now();
      if (!options->diagnostics.empty()) {
        nlohmann::ordered_json guides = nlohmann::ordered_json::array();
        auto terms = [](const EnergyTerms& e) {
          return nlohmann::ordered_json{{"elastic", e.elastic}, {"gravity", e.gravity}, {"collision", e.collision}, {"total", e.total()}};
        };
        for (const GuideReport& r : result.reports)
          guides.push_back({{"follicle", r.follicle}, {"coordinates", r.coordinates}, {"start", terms(r.start)},
                            {"end", terms(r.end)}, {"stages", r.stages}, {"evaluations", r.evaluations},
                            {"stoppedOn", name(r.stop)}});
        nlohmann::ordered_json doc = {{"setup", options->setup}, {"configDigest", config.digest()}, {"guides", guides}};
        writeFileAtomic(options->diagnostics, doc.dump(1) + "\n");
      }
      writeStrands(options->output, result.guides);
      auto t3 = std::chrono::steady_clock::now();
      double growSeconds = std::chrono::duration<double>(t2 - t1).count();
      stats.time("read", std::chrono::duration<double>(t1 - t0).count());
      stats.time("grow", growSeconds);
      stats.time("write", std::chrono::duration<double>(t3 - t2).count());
      stats.counts()["guides"] = result.guides.strandCount();
      stats.counts()["points"] = result.guides.pointCount();
      stats.counts()["energyEvaluations"] = result.evaluations;
      int onEpsilon = 0;
      for (const GuideReport& r : result.reports) onEpsilon += r.stop == RosenbrockStop::kEpsilon || r.stop == RosenbrockStop::kStalled;
      stats.counts()["convergedOnEpsilon"] = onEpsilon;
      stats.counts()["stoppedOnMaxIter"] = static_cast<int>(result.reports.size()) - onEpsilon;
      note(options->common, "grow: wrote " + options->output + " (" + std::to_string(result.guides.strandCount()) +
                                " guides, " + std::to_string(result.evaluations) + " energy evaluations, " +
                                std::to_string(growSeconds) + " s)");
      stats.write(options->common);
    });
  });
}

}  // namespace hairgen::cli
