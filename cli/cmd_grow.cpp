// hairgen grow SETUP -o guides.{hair,gltf,glb}: one Super-Helix guide per wick vertex.
#include "cli/commands.h"
#include "cli/common.h"
#include "libcore/config/setup.h"
#include "libcore/io/hair_cache.h"
#include "libcore/io/obj_io.h"
#include "libcore/model/shards.h"
#include "libcore/util/file_util.h"
#include "libcore/util/json.h"
#include "stages/grow.h"

namespace hairgen::cli {

namespace {

void writeDiagnostics(const std::string& file, const std::string& setup, const Config& config,
                      const GrowResult& result) {
  nlohmann::ordered_json guides = nlohmann::ordered_json::array();
  auto terms = [](const EnergyTerms& e) {
    return nlohmann::ordered_json{
        {"elastic", e.elastic}, {"gravity", e.gravity}, {"collision", e.collision}, {"total", e.total()}};
  };
  for (const GuideReport& r : result.reports)
    guides.push_back({{"follicle", r.follicle},
                      {"coordinates", r.coordinates},
                      {"start", terms(r.start)},
                      {"end", terms(r.end)},
                      {"stages", r.stages},
                      {"evaluations", r.evaluations},
                      {"stoppedOn", name(r.stop)}});
  nlohmann::ordered_json doc = {{"setup", setup}, {"configDigest", config.digest()}, {"guides", guides}};
  writeFileAtomic(file, jsonText(doc, 1) + "\n");
}

}  // namespace

GrowResult growStage(const CommonOptions& common, const Config& config, const Mesh& wick, Stats& stats,
                     std::optional<ShardRange> shard) {
  const size_t guides = shard ? shard->end - shard->first : wick.vertexCount();
  note(common,
       "grow: " + std::to_string(guides) + " guides from " + config.setup.wickModel.path.string() +
           (shard ? " (shard " + std::to_string(shard->index) + "/" + std::to_string(shard->count) +
                        ": vertices " + std::to_string(shard->first) + "-" + std::to_string(shard->end) + ")"
                  : ""));
  Stopwatch clock;
  Progress progress("grow", "guides", guides, !common.quiet);
  GrowResult result = grow(wick, config.hairstyle, config.collision,
                           GrowOptions{config.digest(), &progress, common.force, shard});
  double seconds = clock.lap();
  const std::string applied = config.setup.meshConversion.describe();
  if (!applied.empty()) result.guides.provenance.conversion = "wick: " + applied;
  stats.time("grow", seconds);
  stats.counts()["guides"] = result.guides.strandCount();
  stats.counts()["guidePoints"] = result.guides.pointCount();
  stats.counts()["energyEvaluations"] = result.evaluations;
  int onEpsilon = 0;
  for (const GuideReport& r : result.reports)
    onEpsilon += r.stop == MinimiserStop::kEpsilon || r.stop == MinimiserStop::kStalled;
  stats.counts()["convergedOnEpsilon"] = onEpsilon;
  stats.counts()["stoppedOnMaxIter"] = static_cast<int>(result.reports.size()) - onEpsilon;
  note(common, "grow: " + std::to_string(result.guides.strandCount()) + " guides, " +
                   std::to_string(result.evaluations) + " energy evaluations in " + formatSeconds(seconds));
  return result;
}

void registerGrow(CLI::App& app, int& exitCode) {
  struct Options {
    CommonOptions common;
    std::string setup, output, diagnostics, shard;
  };
  auto options = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand(
      "grow",
      "Grow one guide per wick vertex: a Super-Helix at its static equilibrium (elasticity, gravity, "
      "collisions), or Anjyo's cantilever beam (Model cantilever)");
  cmd->add_option("SETUP", options->setup, "The Setup file")->required();
  cmd->add_option("-o,--output", options->output,
                  "Guides to write: " + hairExtensionList() + " (written atomically)")
      ->type_name("FILE")
      ->required();
  cmd->add_option("--diagnostics", options->diagnostics,
                  "Write per guide: follicle, generalised coordinates, energy terms at start and end, stages "
                  "(Minimiser bfgs: iterations), evaluations, why it stopped")
      ->type_name("FILE.json");
  cmd->add_option(
         "--shard", options->shard,
         "Grow only shard K of N: the guides of the K-th of N equal ranges of wick vertices, written "
         "as .hair with the range in its provenance; `hairgen merge` joins the N shards into the "
         "file a whole run writes")
      ->type_name("K/N");
  addCommonFlags(*cmd, options->common, true);
  cmd->callback([options, &exitCode] {
    exitCode = runCommand("grow", options->common, [&] {
      Stats stats("grow");
      const HairFormat format = hairFormatOf(options->output);
      requireWritableOutput(options->output);
      if (!options->diagnostics.empty()) requireWritableOutput(options->diagnostics);
      const std::optional<ShardSpec> shard = shardOption(options->shard, options->output, format);
      Stopwatch clock;
      Config config = loadStageConfig(options->setup, options->common, SetupUse::kGrow, stats);
      const Scene scene = readScene(options->common, config, true, false, stats);
      stats.time("read", clock.lap());
      std::optional<ShardRange> range;
      if (shard) range = shardRange(shard->index, shard->count, scene.wick->vertexCount());
      GrowResult result = growStage(options->common, config, *scene.wick, stats, range);
      clock.lap();  // growStage timed the growing itself
      if (!options->diagnostics.empty())
        writeDiagnostics(options->diagnostics, options->setup, config, result);
      writeStrands(options->output, result.guides);
      stats.time("write", clock.lap());
      note(options->common, "grow: wrote " + options->output);
      stats.write(options->common);
    });
  });
}

}  // namespace hairgen::cli
