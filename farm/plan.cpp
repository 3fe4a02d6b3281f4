// The farm plan: the tasks of `hairgen run`, split. Shards are equal ranges of wick vertices (grow) and
// triangles (interpolate); chunks are runs of `chunk` frames. CPU and memory requests come from the
// work estimates `hairgen check` prints (stages/preflight/estimate.h), scaled to each task's share of the
// work.
#include "farm/plan.h"

#include <algorithm>
#include <cmath>

#include "libcore/util/error.h"
#include "libcore/util/json.h"
#include "libcore/util/text.h"
#include "stages/preflight/estimate.h"
#include "stages/shade.h"

namespace hairgen {
namespace {

// What a hairgen process holds before its work: the executable, its libraries, a GL context.
constexpr uint64_t kProcessMiB = 256;
// A task gets one more CPU for every this many seconds of estimated work (up to FarmPlanOptions::maxCpus):
// below it, threads would not pay for the time the scheduler takes to find free cores.
constexpr double kSecondsPerCpu = 20.0;
// A shot's simulation is split into at most this many chained tasks.
constexpr int kSimulationChunks = 4;

struct Request {
  int cpus = 1;
  uint64_t memoryMiB = kProcessMiB;
  double seconds = 0.0;
};

Request request(const WorkEstimate* e, double share, int maxCpus) {
  Request r;
  if (!e) return r;
  r.seconds = e->seconds * share;
  r.cpus = std::clamp(int(std::ceil(r.seconds / kSecondsPerCpu)), 1, std::max(maxCpus, 1));
  r.memoryMiB = kProcessMiB + uint64_t(std::ceil(double(e->bytes) * share / double(1 << 20)));
  return r;
}

std::string framesText(const FrameRange& f) {
  return std::to_string(f.first) + "-" + std::to_string(f.last);
}

// `frames` in runs of `chunk` frames, the last one shorter; counted in 64 bits, so a range that ends at
// the largest int does not overflow.
std::vector<FrameRange> chunksOf(const FrameRange& frames, int chunk) {
  std::vector<FrameRange> chunks;
  for (int64_t first = frames.first; first <= frames.last; first += chunk)
    chunks.push_back({int(first), int(std::min<int64_t>(frames.last, first + chunk - 1))});
  return chunks;
}

// The limits of farm_plan.h on the options and the shot, before any work.
void checkLimits(const Config& config, const FarmPlanOptions& options) {
  if (options.shards < 1 || options.shards > kFarmMaxGroupTasks)
    throw InputError("--shards " + std::to_string(options.shards) + ": from 1 to " +
                     std::to_string(kFarmMaxGroupTasks) + " (the most tasks of one job array)");
  if (options.chunk < 1 || options.chunk > kFarmMaxFrames)
    throw InputError("--chunk " + std::to_string(options.chunk) + ": from 1 to " +
                     std::to_string(kFarmMaxFrames) + " frames");
  if (!config.dynamics.given) return;
  const FrameRange frames{config.dynamics.firstFrame, config.dynamics.lastFrame};
  checkFarmFrames(frames, "the shot's frames (--frames, or Dynamics Frames)");
  const int64_t chunks = (int64_t(frames.count()) + options.chunk - 1) / options.chunk;
  if (chunks > kFarmMaxGroupTasks)
    throw InputError("--chunk " + std::to_string(options.chunk) + ": the shot's " +
                     std::to_string(frames.count()) + " frames make " + std::to_string(chunks) +
                     " render tasks; a plan has at most " + std::to_string(kFarmMaxGroupTasks) +
                     " (a --chunk of at least " +
                     std::to_string((frames.count() + kFarmMaxGroupTasks - 1) / kFarmMaxGroupTasks) + ")");
}

}  // namespace

FarmPlan planFarm(const Config& config, const Mesh& wick, const FarmPlanOptions& options) {
  if (config.setup.load)
    throw InputError(config.setup.file.string() +
                     ": Load true: the coupe is loaded, not grown, so there is nothing to split; a farm "
                     "plan needs a Setup that grows its guides (Load false)");
  checkLimits(config, options);
  FarmPlan plan;
  plan.setup = options.setup;
  plan.directory = options.directory;
  plan.configDigest = config.digest();
  plan.overrides = options.overrides;
  plan.shards = options.shards;
  plan.chunk = options.chunk;
  const bool shot = config.dynamics.given, shaded = wantsShade(config.visuality, config.render);
  if (shot) plan.frames = FrameRange{config.dynamics.firstFrame, config.dynamics.lastFrame};

  const std::vector<WorkEstimate> estimates = estimateRun(config, wick, shaded, true, options.threads);
  auto estimate = [&](const std::string& stage) -> const WorkEstimate* {
    for (const WorkEstimate& e : estimates)
      if (e.stage == stage) return &e;
    return nullptr;
  };
  const std::string& dir = options.directory;
  const std::string& setup = options.setup;
  auto add = [&](std::string id, std::string group, std::vector<std::string> args,
                 std::vector<std::string> inputs, std::vector<std::string> outputs,
                 std::vector<std::string> deps, const Request& r, bool readsSetup) {
    FarmTask t;
    t.id = std::move(id);
    t.group = std::move(group);
    t.command.push_back(options.hairgen);
    t.command.insert(t.command.end(), args.begin(), args.end());
    if (readsSetup) t.command.insert(t.command.end(), options.overrides.begin(), options.overrides.end());
    t.command.insert(t.command.end(), {"--quiet", "--threads", std::to_string(r.cpus)});
    t.inputs = std::move(inputs);
    t.outputs = std::move(outputs);
    t.deps = std::move(deps);
    t.cpus = r.cpus;
    t.memoryMiB = r.memoryMiB;
    t.estimatedSeconds = r.seconds;
    plan.tasks.push_back(std::move(t));
  };
  const int n = options.shards;
  const double share = 1.0 / n;

  // Guides in shards, merged.
  std::vector<std::string> guideShards, growIds, coupeShards, interpolateIds;
  for (int k = 1; k <= n; ++k) {
    const std::string shard = std::to_string(k) + "/" + std::to_string(n);
    guideShards.push_back(dir + "/shards/guides." + std::to_string(k) + ".hair");
    growIds.push_back("grow." + std::to_string(k));
    add(growIds.back(), "grow", {"grow", setup, "--shard", shard, "-o", guideShards.back()}, {setup},
        {guideShards.back()}, {}, request(estimate("grow"), share, options.maxCpus), true);
  }
  const std::string guides = dir + "/guides.hair";
  std::vector<std::string> mergeArgs = {"merge"};
  mergeArgs.insert(mergeArgs.end(), guideShards.begin(), guideShards.end());
  mergeArgs.insert(mergeArgs.end(), {"-o", guides});
  add("merge-guides", "merge-guides", mergeArgs, guideShards, {guides}, growIds, Request{}, false);

  // The rest coupe in shards, merged, shaded.
  for (int k = 1; k <= n; ++k) {
    const std::string shard = std::to_string(k) + "/" + std::to_string(n);
    coupeShards.push_back(dir + "/shards/coupe." + std::to_string(k) + ".hair");
    interpolateIds.push_back("interpolate." + std::to_string(k));
    add(interpolateIds.back(), "interpolate",
        {"interpolate", setup, "--guides", guides, "--shard", shard, "-o", coupeShards.back()},
        {setup, guides}, {coupeShards.back()}, {"merge-guides"},
        request(estimate("interpolate"), share, options.maxCpus), true);
  }
  const std::string coupe = dir + "/coupe.hair";
  mergeArgs = {"merge"};
  mergeArgs.insert(mergeArgs.end(), coupeShards.begin(), coupeShards.end());
  mergeArgs.insert(mergeArgs.end(), {"-o", coupe});
  add("merge-coupe", "merge-coupe", mergeArgs, coupeShards, {coupe}, interpolateIds, Request{}, false);
  std::string rest = coupe, restTask = "merge-coupe";
  if (shaded) {
    rest = dir + "/shaded.hair";
    restTask = "shade";
    add("shade", "shade", {"shade", setup, "--hair", coupe, "-o", rest}, {setup, coupe}, {rest},
        {"merge-coupe"}, request(estimate("shade"), 1.0, options.maxCpus), true);
  }

  if (!shot) {
    const std::string exr = dir + "/beauty.exr", png = dir + "/beauty.png";
    add("render", "render", {"render", setup, "--hair", rest, "-o", exr, "--preview", png}, {setup, rest},
        {exr, png}, {restTask}, request(estimate("render"), 1.0, options.maxCpus), true);
    validateFarmPlan(plan, options.directory + "/plan.json");
    return plan;
  }

  // A shot: the guides simulated chunk by chunk, each chunk restarting from the last frame of the one
  // before (bitwise the same as one run), then every chunk of frames rendered from them in one task:
  // interpolated, re-posed from the shaded rest coupe and rendered in memory, as run does, so no
  // per-frame coupe is written.
  const FrameRange frames = *plan.frames;
  const std::string simPattern = dir + "/sim/guides.####.hair", exrPattern = dir + "/beauty.####.exr",
                    pngPattern = dir + "/beauty.####.png";
  auto frameFiles = [](const std::string& pattern, const FrameRange& f) {
    std::vector<std::string> files;
    for (int i = f.first; i <= f.last; ++i) files.push_back(framePath(pattern, i).string());
    return files;
  };
  const size_t guidePoints = pointsPerGuide(config.hairstyle);
  const WorkEstimate simulation = estimateSimulate(
      config.dynamics, wick.vertexCount() * (guidePoints > 0 ? guidePoints - 1 : 0), frames, options.threads);
  // A frame holds its coupe while it renders: the two estimates' memory together, their times summed.
  WorkEstimate frame;
  for (const char* stage : {"interpolate", "render"})
    if (const WorkEstimate* e = estimate(stage)) {
      frame.bytes += e->bytes;
      frame.seconds += e->seconds;
    }
  // At most kSimulationChunks chained simulation tasks: each link costs a scheduling round, and the
  // simulation is fast (it needs chunks only to resume), so its chunks are longer than the render's.
  const int simChunk = std::max(options.chunk, (frames.count() + kSimulationChunks - 1) / kSimulationChunks);
  std::vector<FrameRange> simulated;
  for (const FrameRange& chunk : chunksOf(frames, simChunk)) {
    const size_t c = simulated.size() + 1;
    std::vector<std::string> simInputs = {setup, guides}, simDeps = {"merge-guides"};
    if (c > 1) {
      simInputs.push_back(framePath(simPattern, chunk.first - 1).string());
      simDeps.push_back("simulate." + std::to_string(c - 1));
    }
    add("simulate." + std::to_string(c), "simulate",
        {"simulate", setup, "--guides", guides, "-o", simPattern, "--frames", framesText(chunk)}, simInputs,
        frameFiles(simPattern, chunk), simDeps,
        request(&simulation, double(chunk.count()) / frames.count(), options.maxCpus), true);
    simulated.push_back(chunk);
  }
  std::vector<std::string> renders;
  int c = 0;
  for (const FrameRange& chunk : chunksOf(frames, options.chunk)) {
    ++c;
    std::vector<std::string> simulates;  // the simulation chunks that hold this chunk's frames
    for (size_t k = 0; k < simulated.size(); ++k)
      if (simulated[k].first <= chunk.last && chunk.first <= simulated[k].last)
        simulates.push_back("simulate." + std::to_string(k + 1));
    std::vector<std::string> args = {"render", setup, "--guides", simPattern};
    std::vector<std::string> inputs = frameFiles(simPattern, chunk), deps = simulates;
    inputs.insert(inputs.begin(), setup);
    if (shaded) {
      args.insert(args.end(), {"--rest", rest});
      inputs.push_back(rest);
      deps.push_back(restTask);
    }
    args.insert(args.end(), {"-o", exrPattern, "--preview", pngPattern, "--frames", framesText(chunk)});
    std::vector<std::string> outputs = frameFiles(exrPattern, chunk), pngs = frameFiles(pngPattern, chunk);
    outputs.insert(outputs.end(), pngs.begin(), pngs.end());
    WorkEstimate work = frame;
    work.seconds *= chunk.count();  // the memory is one frame's: frames render one after another
    Request r = request(&work, 1.0, options.maxCpus);
    add("render." + std::to_string(c), "render", args, inputs, outputs, deps, r, true);
    renders.push_back("render." + std::to_string(c));
  }
  // The preview movie from every frame's PNG, as run makes it.
  const std::string mp4 = dir + "/beauty.mp4", gif = dir + "/beauty.gif";
  add("movie", "movie",
      {"movie", pngPattern, "--frames", framesText(frames), "--fps", formatReal(config.dynamics.frameRate),
       "-o", mp4, "--gif", gif},
      frameFiles(pngPattern, frames), {mp4, gif}, renders, Request{}, false);
  validateFarmPlan(plan, options.directory + "/plan.json");
  return plan;
}

}  // namespace hairgen
