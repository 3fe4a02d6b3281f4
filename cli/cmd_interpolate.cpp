// hairgen interpolate SETUP --guides FILE -o coupe.{hair,gltf,glb}: the full coupe from the guides.
#include "cli/commands.h"
#include "cli/common.h"
#include "libcore/config/setup.h"
#include "libcore/io/hair_cache.h"
#include "libcore/io/obj_io.h"
#include "libcore/util/text.h"
#include "stages/interpolate.h"

namespace hairgen::cli {

void registerInterpolate(CLI::App& app, int& exitCode) {
  struct Options {
    CommonOptions common;
    std::string setup, guides, output;
    UnitOptions units;
  };
  auto options = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand(
      "interpolate",
      "Fill every wick triangle with strands blended from its corner guides (clumping, stray hairs)");
  cmd->add_option("SETUP", options->setup, "The Setup file")->required();
  cmd->add_option("--guides", options->guides,
                  "Guides from `hairgen grow` on the same Setup (.hair, .gltf, .glb, .ply, .data)")
      ->required();
  addUnitFlags(*cmd, options->units, "the guides");
  cmd->add_option("-o,--output", options->output,
                  "Coupe to write: .hair, .gltf, .glb, .ply, .data or .usda (written atomically)")
      ->required();
  addCommonFlags(*cmd, options->common, true);
  cmd->footer(exitCodeHelp());
  cmd->callback([options, &exitCode] {
    exitCode = runCommand("interpolate", options->common, [&] {
      Stats stats("interpolate");
      hairFormatOf(options->output);
      Stopwatch clock;
      Config config = loadStageConfig(options->setup, options->common, SetupUse::kInterpolate, stats);
      Mesh wick = readObj(config.setup.wickModel.path);
      Strands guides = readStrandsAs(options->guides, options->units);
      stats.time("read", clock.lap());
      Strands coupe = interpolateStage(options->common, config, wick, guides, options->guides, stats);
      writeStrands(options->output, coupe);
      stats.time("write", clock.lap());
      note(options->common, "interpolate: wrote " + options->output);
      stats.write(options->common);
    });
  });
}

Strands interpolateStage(const CommonOptions& common, const Config& config, const Mesh& wick,
                         const Strands& guides, const std::string& guidesName, Stats& stats) {
  note(common, "interpolate: " + std::to_string(wick.triangles.size()) + " triangles at " +
                   formatReal(config.hairstyle.hairDensity) + " strands/cm²");
  Stopwatch clock;
  Progress progress("interpolate", "triangles", wick.triangles.size(), !common.quiet);
  Strands coupe = interpolate(wick, guides, config.hairstyle, config.collision,
                              InterpolateOptions{config.digest(), guidesName, &progress, common.force});
  double seconds = clock.lap();
  stats.time("interpolate", seconds);
  stats.counts()["triangles"] = wick.triangles.size();
  stats.counts()["strands"] = coupe.strandCount();
  stats.counts()["points"] = coupe.pointCount();
  note(common, "interpolate: " + std::to_string(coupe.strandCount()) + " strands, " +
                   std::to_string(coupe.pointCount()) + " points in " + formatSeconds(seconds));
  return coupe;
}

}  // namespace hairgen::cli
