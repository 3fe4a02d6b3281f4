// hairgen shade SETUP --hair FILE -o OUT: per-strand shading attributes into the cache.
#include "cli/commands.h"
#include "cli/common.h"
#include "libcore/hair_cache.h"
#include "libcore/setup.h"
#include "libcore/text.h"
#include "stages/shade.h"

namespace hairgen::cli {

Strands shadeStage(const CommonOptions& common, const Config& config, const Strands& coupe, Stats& stats) {
  Stopwatch clock;
  Strands shaded = shade(coupe, config.visuality, config.hairstyle.seed, config.digest());
  stats.time("shade", clock.lap());
  note(common, "shade: per-strand ambient from N(" + formatReal(config.visuality.ambientMean) + ", " +
                   formatReal(config.visuality.ambientDeviation) + ") on " + std::to_string(shaded.strandCount()) +
                   " strands");
  return shaded;
}

void registerShade(CLI::App& app, int& exitCode) {
  struct Options {
    CommonOptions common;
    std::string setup, hair, output;
  };
  auto options = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand(
      "shade", "Per-strand shading attributes: an ambient coefficient from N(AmbientMean, AmbientDeviation), stored "
               "as per-vertex colour");
  cmd->add_option("SETUP", options->setup, "The Setup file (Visuality Info; Hairstyle's Seed)")->required();
  cmd->add_option("--hair", options->hair, "The coupe (.hair, .gltf, .glb)")->required();
  cmd->add_option("-o,--output", options->output, "Shaded coupe to write (.hair, .gltf, .glb)")->required();
  addCommonFlags(*cmd, options->common, true);
  cmd->footer(exitCodeHelp());
  cmd->callback([options, &exitCode] {
    exitCode = runCommand("shade", options->common, [&] {
      Stats stats("shade");
      hairFormatOf(options->output);
      Config config = loadStageConfig(options->setup, options->common, SetupUse::kRender, stats);
      Strands shaded = shadeStage(options->common, config, readStrands(options->hair), stats);
      writeStrands(options->output, shaded);
      note(options->common, "shade: wrote " + options->output);
      stats.write(options->common);
    });
  });
}

}  // namespace hairgen::cli
