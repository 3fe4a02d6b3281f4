// hairgen simulate SETUP --guides FILE -o sim/guides.####.hair [--frames A-B]: the guides through time
// (DESIGN §8), one cache per frame; a range starting after the shot's first frame resumes from the
// frame before it.
#include "cli/commands.h"
#include "cli/common.h"
#include "libcore/io/hair_cache.h"
#include "libcore/util/file_util.h"
#include "libcore/util/frames.h"
#include "libcore/util/progress.h"
#include "libcore/util/text.h"
#include "stages/simulate.h"

namespace hairgen::cli {

namespace {

struct SimulateArgs {
  CommonOptions common;
  std::string setup, guides, output, frames;
};

// What a simulation reads: the rest guides, the frame before a resumed range (when it was written), and
// Model springs' DensityTarget.
struct Inputs {
  Strands rest;
  std::optional<Strands> restart, target;
  std::string restartName;
};

Inputs readInputs(const SimulateArgs& o, const Dynamics& d, const FrameRange& frames) {
  Inputs in{readStrands(o.guides), {}, {}, {}};
  if (frames.first > d.firstFrame) {
    in.restartName = framePath(o.output, frames.first - 1).string();
    if (std::filesystem::exists(in.restartName)) in.restart = readStrands(in.restartName);
  }
  if (d.model == DynamicsModel::kSprings && d.densityTarget.given())
    in.target = readStrands(d.densityTarget.path);
  return in;
}

}  // namespace

void registerSimulate(CLI::App& app, int& exitCode) {
  auto options = std::make_shared<SimulateArgs>();
  CLI::App* cmd = app.add_subcommand(
      "simulate",
      "Move the guides through time under the Setup's Dynamics Info (wind, head motion, gravity): one guide "
      "cache per frame; --frames resumes a split shot from the frame before its first");
  cmd->add_option("SETUP", options->setup, "The Setup file; it names the Dynamics Info")->required();
  cmd->add_option("--guides", options->guides,
                  "The rest guides (`hairgen grow` on the same Setup, any format)")
      ->type_name("FILE")
      ->required();
  cmd->add_option(
         "-o,--output", options->output,
         "Per-frame guides, #### (or %04d) standing for the frame number, e.g. sim/guides.####.hair; "
         ".hair keeps the state a restart needs")
      ->type_name("PATTERN")
      ->required();
  cmd->add_option("--frames", options->frames, "The frames to simulate (default: Dynamics Frames)")
      ->type_name("A-B");
  addCommonFlags(*cmd, options->common, true);
  cmd->callback([options, &exitCode] {
    exitCode = runCommand("simulate", options->common, [&] {
      Stats stats("simulate");
      if (!isFramePattern(options->output))
        throw InputError("-o " + options->output + ": write #### (or %04d) where the frame number goes");
      hairFormatOf(options->output);
      Stopwatch clock;
      Config config = loadStageConfig(options->setup, options->common, SetupUse::kRender, stats);
      readScene(options->common, config, false, false, stats);  // fits any auto collision shape
      const Dynamics& d = config.dynamics;
      const FrameRange frames = options->frames.empty() ? FrameRange{d.firstFrame, d.lastFrame}
                                                        : parseFrameRange(options->frames, "--frames");
      requireWritableOutput(framePath(options->output, frames.first));
      const Inputs in = readInputs(*options, d, frames);
      const Strands& rest = in.rest;
      stats.time("read", clock.lap());
      note(options->common, "simulate: " + std::to_string(rest.strandCount()) + " guides, frames " +
                                std::to_string(frames.first) + "-" + std::to_string(frames.last) + " at " +
                                formatReal(d.frameRate) + " fps, " + std::to_string(d.substeps) +
                                " substeps");
      Progress progress("simulate", "frames", size_t(frames.count()), !options->common.quiet);
      SimulateOptions simOptions{config.digest(),
                                 frames,
                                 in.restart ? &*in.restart : nullptr,
                                 in.restartName,
                                 &progress,
                                 options->common.force,
                                 in.target ? &*in.target : nullptr};
      double writing = 0.0;
      simulate(rest, config, simOptions, [&](int frame, const Strands& guides) {
        Stopwatch write;
        writeStrands(framePath(options->output, frame), guides);
        keepCommittedOutputs();  // a finished frame stays, whatever a later one does
        writing += write.lap();
      });
      progress.finish();
      const double total = clock.lap();
      stats.time("simulate", total - writing);
      stats.time("write", writing);
      stats.counts()["guides"] = rest.strandCount();
      stats.counts()["frames"] = frames.count();
      note(options->common, "simulate: wrote " + framePath(options->output, frames.first).string() + " to " +
                                framePath(options->output, frames.last).filename().string() + " in " +
                                formatSeconds(total));
      stats.write(options->common);
    });
  });
}

}  // namespace hairgen::cli
