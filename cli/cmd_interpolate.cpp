// hairgen interpolate SETUP --guides FILE -o coupe.{hair,gltf,glb}: the full coupe from the guides.
#include "cli/commands.h"
#include "cli/common.h"
#include "libcore/config/setup.h"
#include "libcore/io/hair_cache.h"
#include "libcore/io/obj_io.h"
#include "libcore/model/shards.h"
#include "libcore/util/file_util.h"
#include "libcore/util/frames.h"
#include "libcore/util/text.h"
#include "stages/interpolate.h"
#include "stages/simulate.h"

namespace hairgen::cli {

namespace {

struct InterpolateArgs {
  CommonOptions common;
  std::string setup, guides, output, frames, shard;
  UnitOptions units;
};

// --frames: every frame of a simulated sequence, each with the same strands, ids and weights.
void interpolateSequence(const InterpolateArgs& o, const Config& config, const Mesh& wick, Stats& stats) {
  Stopwatch clock;
  const FrameRange frames = parseFrameRange(o.frames, "--frames");
  for (const std::string* pattern : {&o.guides, &o.output})
    if (!isFramePattern(*pattern))
      throw InputError(*pattern + ": with --frames, write #### where the frame number goes");
  requireWritableOutput(framePath(o.output, frames.first));
  const HeadMotion head = headMotionOf(config);
  Progress progress("interpolate", "frames", size_t(frames.count()), !o.common.quiet);
  // Every frame has the same strands: each is written over the last one's arrays.
  Strands coupe;
  for (int f = frames.first; f <= frames.last; ++f) {
    const std::filesystem::path in = framePath(o.guides, f);
    const Strands guides = readStrandsAs(in, o.units);
    stats.add("read", clock.lap());
    InterpolateOptions frameOptions{config.digest(), in.string(), nullptr, o.common.force,
                                    head.pose(f).matrix()};
    interpolateInto(wick, guides, config.hairstyle, config.collision, frameOptions, coupe);
    stats.add("interpolate", clock.lap());
    writeStrands(framePath(o.output, f), coupe);
    keepCommittedOutputs();  // a finished frame stays, whatever a later one does
    stats.add("write", clock.lap());
    stats.counts()["strands"] = coupe.strandCount();
    stats.counts()["points"] = coupe.pointCount();
    progress.advance();
  }
  progress.finish();
  stats.counts()["frames"] = frames.count();
  note(o.common, "interpolate: wrote " + framePath(o.output, frames.first).string() + " to " +
                     framePath(o.output, frames.last).filename().string());
}

}  // namespace

void registerInterpolate(CLI::App& app, int& exitCode) {
  auto options = std::make_shared<InterpolateArgs>();
  CLI::App* cmd = app.add_subcommand(
      "interpolate",
      "Fill every wick triangle with strands blended from its corner guides (clumping, stray hairs); with "
      "--frames, every frame of a simulated sequence, each with the same strands, ids and weights");
  cmd->add_option("SETUP", options->setup, "The Setup file")->required();
  cmd->add_option("--guides", options->guides,
                  "Guides from `hairgen grow` on the same Setup (" + readHairExtensionList() +
                      "); with --frames a pattern such as sim/guides.####.hair")
      ->type_name("FILE")
      ->required();
  addUnitFlags(*cmd, options->units, "the guides");
  cmd->add_option("-o,--output", options->output,
                  "Coupe to write: " + hairExtensionList() + " (written atomically); with --frames a pattern")
      ->type_name("FILE")
      ->required();
  cmd->add_option("--frames", options->frames, "Interpolate these frames of a sequence")->type_name("A-B");
  cmd->add_option(
         "--shard", options->shard,
         "Fill only shard K of N: the K-th of N equal ranges of wick triangles, with the whole run's "
         "strand ids and random numbers, written as .hair with the range in its provenance; "
         "`hairgen merge` joins the N shards into the file a whole run writes")
      ->type_name("K/N")
      ->excludes("--frames");
  addCommonFlags(*cmd, options->common, true);
  cmd->callback([options, &exitCode] {
    exitCode = runCommand("interpolate", options->common, [&] {
      Stats stats("interpolate");
      const HairFormat format = hairFormatOf(options->output);
      if (!isFramePattern(options->output)) requireWritableOutput(options->output);
      const std::optional<ShardSpec> shard = shardOption(options->shard, options->output, format);
      Stopwatch clock;
      Config config = loadStageConfig(options->setup, options->common, SetupUse::kInterpolate, stats);
      const Scene scene = readScene(options->common, config, true, false, stats);
      const Mesh& wick = *scene.wick;
      if (options->frames.empty()) {
        Strands guides = readStrandsAs(options->guides, options->units);
        stats.time("read", clock.lap());
        std::optional<ShardRange> range;
        if (shard) range = shardRange(shard->index, shard->count, wick.triangles.size());
        Strands coupe =
            interpolateStage(options->common, config, wick, guides, options->guides, stats, range);
        writeStrands(options->output, coupe);
        stats.time("write", clock.lap());
        note(options->common, "interpolate: wrote " + options->output);
        stats.write(options->common);
        return;
      }
      interpolateSequence(*options, config, wick, stats);
      stats.write(options->common);
    });
  });
}

Strands interpolateStage(const CommonOptions& common, const Config& config, const Mesh& wick,
                         const Strands& guides, const std::string& guidesName, Stats& stats,
                         std::optional<ShardRange> shard) {
  const size_t triangles = shard ? shard->end - shard->first : wick.triangles.size();
  note(common,
       "interpolate: " + std::to_string(triangles) + " triangles at " +
           formatReal(config.hairstyle.hairDensity) + " strands/cm²" +
           (shard ? " (shard " + std::to_string(shard->index) + "/" + std::to_string(shard->count) +
                        ": triangles " + std::to_string(shard->first) + "-" + std::to_string(shard->end) + ")"
                  : ""));
  Stopwatch clock;
  Progress progress("interpolate", "triangles", triangles, !common.quiet);
  InterpolateOptions interpolation{config.digest(), guidesName,      &progress,
                                   common.force,    glm::dmat4(1.0), shard};
  Strands coupe = interpolate(wick, guides, config.hairstyle, config.collision, interpolation);
  double seconds = clock.lap();
  const std::string applied = config.setup.meshConversion.describe();
  if (!applied.empty()) coupe.provenance.conversion = "wick: " + applied;
  stats.time("interpolate", seconds);
  stats.counts()["triangles"] = triangles;
  stats.counts()["strands"] = coupe.strandCount();
  stats.counts()["points"] = coupe.pointCount();
  note(common, "interpolate: " + std::to_string(coupe.strandCount()) + " strands, " +
                   std::to_string(coupe.pointCount()) + " points in " + formatSeconds(seconds));
  return coupe;
}

}  // namespace hairgen::cli
