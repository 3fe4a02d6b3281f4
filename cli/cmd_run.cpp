// hairgen run [SETUP] [-o DIR]: the stages in one process, with the same files the stages give when
// chained by hand. With no SETUP it runs the bundled default coupe.
#include <cstdlib>
#include <filesystem>

#include <tbb/task_arena.h>
#include <iostream>
#include <optional>
#include <vector>

#include "cli/commands.h"
#include "cli/common.h"
#include "libcore/config/setup.h"
#include "libcore/io/hair_cache.h"
#include "libcore/io/movie.h"
#include "libcore/io/obj_io.h"
#include "libcore/io/usd_io.h"
#include "libcore/physics/head_motion.h"
#include "libcore/util/error.h"
#include "libcore/util/file_util.h"
#include "libcore/util/frames.h"
#include "libcore/util/progress.h"
#include "libcore/util/text.h"
#include "stages/interpolate.h"
#include "stages/preflight/estimate.h"
#include "stages/shade.h"
#include "stages/shot.h"
#include "stages/simulate.h"

namespace hairgen::cli {
namespace {

namespace fs = std::filesystem;

// configs/default/setup.txt under $HAIRGEN_DATA, beside the executable's build tree (build/ → ..), or
// in an installed share/hairgen.
fs::path defaultSetup() {
  std::vector<fs::path> candidates;
  if (const char* data = std::getenv("HAIRGEN_DATA"); data && *data)
    candidates.push_back(fs::path(data) / "configs/default/setup.txt");
  std::error_code ec;
  fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    for (fs::path dir = exe.parent_path(); !dir.empty() && dir != dir.root_path(); dir = dir.parent_path()) {
      candidates.push_back(dir / "configs/default/setup.txt");
      candidates.push_back(dir / "share/hairgen/configs/default/setup.txt");
    }
  }
  for (const fs::path& c : candidates)
    if (fs::is_regular_file(c, ec)) return c;
  throw InputError(
      "no SETUP given and the default coupe (configs/default/setup.txt) was not found next to the "
      "executable; name a Setup file or set HAIRGEN_DATA to the folder that holds configs/");
}

// The shot as one USD stage, DIR/shot.usda: the written frames' guides time-sampled (/hair/guides) and
// the rest coupe (/hair/strands), whose groom_closest_guides name the guides, as Unreal's guide caches
// have it: a DCC interpolates the strands from the moving guides.
void writeShotUsd(const fs::path& out, const fs::path& simPattern, const Strands& restCoupe,
                  FrameRange frames, double frameRate) {
  UsdShot shot;
  shot.frames = frames;
  shot.framesPerSecond = frameRate;
  shot.guides =
      UsdShotPrim{[&](int f) { return readStrands(framePath(simPattern, f)); }, simPattern.string()};
  shot.strands = UsdShotPrim{[&](int) { return restCoupe; }, "the rest coupe", false};
  writeUsdShot(out / "shot.usda", shot);
}

// A shot (the Setup names a Dynamics Info): the guides simulated frame by frame into DIR/sim, and each
// frame interpolated, shaded like the rest coupe (its normals re-posed, its colours kept) and rendered
// to DIR/beauty.####.exr and .png, then the preview movies DIR/beauty.mp4 and DIR/beauty.gif. The
// per-frame coupes stay in memory: a shot of a full coupe would write gigabytes of them. With
// `motionVectors`, each frame's EXR has the motion layer (the first frame's is 0: nothing came before).
// Only the frames of `wanted` are written and rendered (run --frames); the shot is still simulated from
// its first frame, and the frames a written one depends on (the first, at which an auto camera aims,
// and with motion vectors the one before) are interpolated in memory, so every file equals the whole
// run's byte for byte.
void runShot(const CommonOptions& common, const Config& config, const Mesh& wick, const Strands& guides,
             const Strands& restCoupe, const fs::path& out, FrameRange wanted, bool render,
             bool motionVectors, Stats& stats) {
  const Dynamics& d = config.dynamics;
  const FrameRange frames{d.firstFrame, wanted.last};  // simulated
  std::optional<Mesh> head;
  if (render && config.setup.headModel.given()) head = readHead(config);
  const bool shaded = wantsShade(config.visuality, config.render);
  const ShotInputs inputs{
      &config,     &wick, shaded ? &restCoupe : nullptr, head ? &*head : nullptr, headMotionOf(config),
      common.force};
  std::unique_ptr<GlContext> gl;
  if (render) gl = openDevice(common, config, stats);
  const fs::path simPattern = out / "sim" / "guides.####.hair", exrPattern = out / "beauty.####.exr",
                 pngPattern = out / "beauty.####.png";
  note(common, "run: a shot of frames " + std::to_string(wanted.first) + "-" + std::to_string(wanted.last) +
                   " at " + formatReal(d.frameRate) + " fps");
  Progress progress("run", "frames", size_t(frames.count()), !common.quiet);
  Stopwatch clock;
  std::optional<Strands> firstCoupe;
  ShotMotion before;            // with motion vectors, the frame before
  RenderOptions renderOptions;  // an auto camera aims at the shot's first frame and holds still
  SimulateOptions simOptions;
  simOptions.configDigest = config.digest();
  simOptions.frames = frames;
  simOptions.force = common.force;
  std::optional<Strands> target;  // Model springs' DensityTarget
  if (d.model == DynamicsModel::kSprings && d.densityTarget.given())
    target = readStrands(d.densityTarget.path);
  simOptions.densityTarget = target ? &*target : nullptr;
  simulate(guides, config, simOptions, [&](int f, const Strands& frameGuides) {
    stats.add("simulate", clock.lap());
    const bool written = f >= wanted.first;
    if (written) {
      writeStrands(framePath(simPattern, f), frameGuides);
      keepCommittedOutputs();  // a finished frame stays, whatever a later one does
      stats.add("write", clock.lap());
    }
    const bool needed = written || f == frames.first || (motionVectors && f == wanted.first - 1);
    if (!render || !needed) return progress.advance();
    ShotFrame frame = shotFrame(inputs, f, frameGuides, framePath(simPattern, f).string());
    stats.add("interpolate", clock.lap());
    if (!firstCoupe) renderOptions.framing = &firstCoupe.emplace(frame.coupe);
    if (!written) {  // only what a written frame needs
      if (motionVectors) before.keep(std::move(frame));
      return progress.advance();
    }
    const FrameBefore frameBefore = motionVectors ? before.before(frame) : FrameBefore{};
    RenderOutput image = renderStage(common, config, *gl, frame.coupe, frame.head ? &*frame.head : nullptr,
                                     renderOptions, stats, motionVectors ? &frameBefore : nullptr);
    if (motionVectors) before.keep(std::move(frame));
    clock.lap();
    writeRenderOutputs(config, image, framePath(exrPattern, f).string(), "",
                       framePath(pngPattern, f).string(), f);
    keepCommittedOutputs();
    stats.add("write", clock.lap());
    progress.advance();
  });
  progress.finish();
  stats.counts()["frames"] = wanted.count();
  writeShotUsd(out, simPattern, restCoupe, wanted, d.frameRate);
  keepCommittedOutputs();
  stats.add("write", clock.lap());
  if (!render) return;
  clock.lap();
  MovieOptions movie;
  movie.frameRate = d.frameRate;
  // The frames are the shot; the movie only previews them. One that cannot be made is a warning (even
  // with --quiet) and run still succeeds, so a farm script does not render the shot again for it.
  try {
    if (writeMovie(pngPattern, wanted, out / "beauty.mp4", out / "beauty.gif", movie))
      note(common, "run: wrote " + framePath(exrPattern, wanted.first).string() + " to " +
                       framePath(exrPattern, wanted.last).filename().string() +
                       ", beauty.mp4 and beauty.gif");
    else
      note(common,
           "run: ffmpeg is not installed, so no preview movie; the frames are " + pngPattern.string());
  } catch (const Error& e) {
    std::cerr << "hairgen run: warning: no preview movie: " << oneLine(e.what()) << "; the frames are kept\n";
  }
  stats.add("movie", clock.lap());
}

// DIR made, and writable: a name that is already something else (or a link to nothing) is bad usage;
// a folder that cannot be made (read-only file system, permissions) is the work failing to write.
void makeOutputFolder(const fs::path& out, bool shot) {
  try {
    createOutputFolder(out);
  } catch (const Error& e) {
    throw Error(e.code(), {}, "-o " + out.string() + ": cannot create the output folder: " + e.what());
  }
  // Before minutes of growing: a folder it cannot write in, or a name it writes that is taken by a folder
  // (or, for the shot's sim/, by a file), is found now.
  std::vector<fs::path> names = {"guides.hair", "coupe.hair", "shaded.hair", "beauty.exr", "beauty.png"};
  if (shot)
    names.insert(names.end(),
                 {fs::path("sim") / "guides.0001.hair", "shot.usda", "beauty.mp4", "beauty.gif"});
  for (const fs::path& name : names) requireWritableOutput(out / name);
}

// What a run renders: the wick and the guides grown on it (none when the Setup Loads a coupe), and the
// coupe.
struct RunCoupe {
  Mesh wick;
  Strands guides;
  Strands coupe;
};

// The coupe loaded, or grown and interpolated (DIR/guides.hair, DIR/coupe.hair); shaded when the Setup
// asks (DIR/shaded.hair) and saved where it says Save.
RunCoupe runCoupe(const CommonOptions& common, Config& config, const fs::path& out, bool render, Stats& stats,
                  Stopwatch& clock) {
  RunCoupe made;
  Strands& coupe = made.coupe;
  Mesh& wick = made.wick;
  if (config.setup.load && config.dynamics.given)
    throw InputError(config.setup.file.string() +
                     ": Load and DynamicsInfo together: a shot simulates the guides, "
                     "which a loaded coupe does not have; grow them (Load false)");
  if (config.setup.load) {
    coupe = readStrands(config.setup.loadFile.path);
    note(common, "run: loaded " + config.setup.loadFile.path.string() + " (" +
                     std::to_string(coupe.strandCount()) + " strands)");
  } else {
    wick = *readScene(common, config, true, false, stats).wick;
    stats.add("read", clock.lap());
    if (wick.triangles.empty())  // refused before minutes of growing, not after
      throw InputError({config.setup.wickModel.path.string(), 0},
                       "the wick has no faces, only points (roots): `hairgen grow` grows guides on them, "
                       "but run interpolates strands over a surface and needs one (a scalp mesh)");
    // Every stage's work is estimated before the first starts: a coupe that cannot be rendered is
    // refused before minutes of growing.
    for (const WorkEstimate& e : estimateRun(config, wick, wantsShade(config.visuality, config.render),
                                             render, size_t(tbb::this_task_arena::max_concurrency())))
      requireFits(e, common.force);
    made.guides = growStage(common, config, wick, stats).guides;
    const fs::path guidesFile = out / "guides.hair";
    clock.lap();
    writeStrands(guidesFile, made.guides);
    double writing = clock.lap();
    coupe = interpolateStage(common, config, wick, made.guides, guidesFile.string(), stats);
    clock.lap();
    writeStrands(out / "coupe.hair", coupe);
    stats.time("write", writing + clock.lap());
    note(common, "run: wrote " + guidesFile.string() + " and " + (out / "coupe.hair").string());
  }
  if (wantsShade(config.visuality, config.render)) {
    coupe = shadeStage(common, config, std::move(coupe), stats).coupe;
    clock.lap();
    writeStrands(out / "shaded.hair", coupe);
    stats.add("write", clock.lap());
  }
  if (config.setup.save) {
    writeStrands(config.setup.saveFile.path, coupe);
    note(common, "run: saved the coupe to " + config.setup.saveFile.path.string());
  }
  return made;
}

// A still: DIR/beauty.exr and DIR/beauty.png.
void runStill(const CommonOptions& common, const Config& config, const Strands& coupe, const fs::path& out,
              Stats& stats, Stopwatch& clock) {
  std::optional<Mesh> head;
  if (config.setup.headModel.given()) head = readHead(config);
  const std::unique_ptr<GlContext> gl = openDevice(common, config, stats);
  RenderOutput image = renderStage(common, config, *gl, coupe, head ? &*head : nullptr, {}, stats);
  clock.lap();
  writeRenderOutputs(config, image, (out / "beauty.exr").string(), "", (out / "beauty.png").string());
  stats.add("write", clock.lap());
  note(common, "run: wrote " + (out / "beauty.exr").string() + " and " + (out / "beauty.png").string());
}

// run --frames A-B (none: Dynamics Frames, on a still too), within the shot's frames.
FrameRange shotFrames(const Config& config, const std::string& text, const std::string& setup) {
  const Dynamics& d = config.dynamics;
  if (text.empty()) return {d.firstFrame, d.lastFrame};
  requireShotForFrames(config, setup);
  const FrameRange frames = parseFrameRange(text, "--frames");
  if (frames.first < d.firstFrame || frames.last > d.lastFrame)
    throw InputError("--frames " + text + ": the shot's frames are " + std::to_string(d.firstFrame) + "-" +
                     std::to_string(d.lastFrame) + " (Dynamics Frames)");
  return frames;
}

}  // namespace

void registerRun(CLI::App& app, int& exitCode) {
  struct Options {
    CommonOptions common;
    std::string setup, outDir, frames;
    bool noRender = false, motion = false;
  };
  auto options = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand(
      "run",
      "Run the stages in one process: grow and interpolate (or Load a saved coupe), shade when the Setup "
      "asks, then render. A still writes DIR/guides.hair, DIR/coupe.hair, DIR/shaded.hair (only when the "
      "Setup shades), DIR/beauty.exr and DIR/beauty.png; a shot (the Setup names a Dynamics Info) also "
      "simulates the guides into DIR/sim/guides.####.hair, writes them with the rest coupe as one animated "
      "USD "
      "stage DIR/shot.usda, and renders DIR/beauty.####.exr and .png and the movie DIR/beauty.mp4 and .gif. "
      "Each file equals what the stage run alone writes");
  cmd->add_option("SETUP", options->setup, "The Setup file (default: the bundled configs/default/setup.txt)");
  cmd->add_option("-o,--output", options->outDir,
                  "Output folder (default: out/NAME, NAME the Setup's folder)")
      ->type_name("DIR");
  cmd->add_option("--frames", options->frames,
                  "On a shot, only these frames (within Dynamics Frames), equal to the same frames of the "
                  "whole shot: it is simulated from its first frame, and only A to B are written")
      ->type_name("A-B");
  cmd->add_flag("--no-render", options->noRender, "Stop after the coupe (no EXR, no preview)");
  cmd->add_flag("--motion", options->motion,
                "On a shot, motion vectors in every frame's EXR (the layer motion.u, motion.v, pixels "
                "moved since the frame before)");
  addCommonFlags(*cmd, options->common, true);
  cmd->callback([options, &exitCode] {
    exitCode = runCommand("run", options->common, [&] {
      Stats stats("run");
      fs::path setup = options->setup.empty() ? defaultSetup() : fs::path(options->setup);
      fs::path out = options->outDir.empty() ? fs::path("out") / fs::absolute(setup).parent_path().filename()
                                             : fs::path(options->outDir);
      Stopwatch clock;
      Config config = loadStageConfig(setup, options->common, SetupUse::kRun, stats);
      stats.time("read", clock.lap());
      const FrameRange frames = shotFrames(config, options->frames, setup.string());
      if (options->motion && (!config.dynamics.given || options->noRender))
        throw InputError(setup.string() + ": --motion renders motion vectors of a shot, and " +
                         (options->noRender ? "--no-render renders nothing"
                                            : "this Setup names no Dynamics Info (DynamicsInfo FILE)"));
      makeOutputFolder(out, config.dynamics.given);
      const RunCoupe made = runCoupe(options->common, config, out, !options->noRender, stats, clock);
      if (config.dynamics.given)
        runShot(options->common, config, made.wick, made.guides, made.coupe, out, frames, !options->noRender,
                options->motion, stats);
      else if (!options->noRender)
        runStill(options->common, config, made.coupe, out, stats, clock);
      stats.write(options->common);
    });
  });
}

}  // namespace hairgen::cli
