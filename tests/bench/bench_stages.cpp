// Stage benchmarks on coupe 3 (head ellipsoid and front sphere) and the bundled wick (759 follicles).
//   EnergyEvaluation:   one thread, energies at the minimised coordinates of 50 guides, so
//                       items_per_second is energy evaluations per second per core.
//   GrowCoupe3:         the whole grow stage on every core, counters guides/s and evaluations/s.
//   GrowDefault:        the same on the default coupe (configs/default), what the README's first
//                       command grows.
//   GrowCoupe3Bfgs, GrowDefaultBfgs: the same with `Minimiser bfgs` (an evaluation is the energy with
//                       its gradient).
//   InterpolateCoupe3:  ~150,000 strands of 64 vertices from coupe 3's guides, every core, into a fresh
//                       coupe each time, as `hairgen interpolate` makes a still: the kernel's faulting
//                       in and clearing of ~230 MB of new pages is part of the figure.
//   InterpolateCoupe3Frames: the same coupe into one reused Strands, as `interpolate --frames` does frame
//                       after frame: the steady cost of a frame, its arrays already in place.
//   ShadeCoupe3:        `shade` on that 150,000-strand coupe with coupe 3's Render Info (grid, signed
//                       distance, normals), every core; counters give the grid's size and each part's
//                       seconds. Copying the coupe in and freeing the result are left out of the time.
//   CantileverStyling:  Anjyo's figures, 20,000 hairs of 20 segments bent around the head ellipsoid.
//   SimulateAnjyo:      those hairs through 25 frames of the gust shot while the head turns.
//   ReadCache/WriteCache: the 150,000-strand coupe's .hair (points, tangents, ids, weights: ~240 MB at 64
//                       vertices) from and to a file in the system's temporary folder, every core;
//                       bytes_per_second is the file's size over the time.
//   SimulateSprings:    Model springs, 10,000 keyhairs of 32 particles through a head turn with
//                       velocity smoothing (Petrovic et al. 2006 §5).
//   Render/strands/width/height/samples: the render stage on coupe 3 (65 points a strand) with the head
//                       and shadows, through whatever EGL opens (the label names it: llvmpipe here);
//                       counters give each pass's seconds. At 150,000 strands, 1920×1080, Samples 1,
//                       the GPU passes (light depth, deep opacity, shading: passes_s) against 5 ms on a
//                       GPU (issue 34; no target on a software rasteriser).
//   RenderCommand:      the whole `hairgen render` of that coupe's cache at 1920×1080, Samples 1, a child
//                       process: wall time against 0.3 s on a GPU and 2 s on a software rasteriser
//                       (issue 34), peak memory (peak_MB) against 3× the cache (peak_of_target).
//   RenderSequence/frames: the render stage frame after frame on one context (as `render --frames`),
//                       the coupe moved between frames: seconds a frame (frame_s) against 0.1 s on a GPU.
//   Readback/pbo:       the beauty's seven planes read back at 1920×1080: 0 as readBack did before,
//                       1 and 2 through the pixel-pack buffer (readback.h), channel by channel and
//                       whole textures.
//   DeviceStart:        opening the EGL context and the first render of one strand (the programs
//                       compiled): what `hairgen render` spends before its first pass. Run it alone
//                       (--benchmark_filter=DeviceStart): after another benchmark's context the display
//                       is already initialised, and the label says so.
// The render benchmarks find hairgen and the sources where they were built; HAIRGEN_BENCH_BINARY and
// HAIRGEN_BENCH_SOURCE name others (a build carried to another machine: scripts/device-check.sh).
// Every benchmark with a target gives `of_target` (its figure over the target: 1 or more meets it) and
// the target; after the runs, a table lists them all (TargetTable, at the end).
#include <benchmark/benchmark.h>

#include <spawn.h>
#include <sys/resource.h>
#include <sys/wait.h>

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <map>
#include <ostream>
#include <string>
#include <vector>

#include <tbb/global_control.h>
#include <tbb/info.h>

#include "libcore/config/setup.h"
#include "libcore/io/gltf_io.h"
#include "libcore/io/hair_io.h"
#include "libcore/io/obj_io.h"
#include "libcore/physics/cantilever.h"
#include "libcore/render/gl_context.h"
#include "libcore/render/gl_resources.h"
#include "libcore/render/readback.h"
#include "libcore/util/stopwatch.h"
#include "stages/grow.h"
#include "stages/interpolate.h"
#include "stages/render.h"
#include "stages/shade.h"
#include "stages/simulate.h"

extern char** environ;  // what the child inherits (POSIX declares it nowhere)

namespace hairgen {
namespace {

// The issues' targets, each printed beside its figure as `of_target`: the figure over its target, so 1
// or more meets it (issue 20 for the stages and caches, 15 and 16 for the dynamics).
constexpr double kGrowCoupe3GuidesPerSecond = 5000.0, kGrowDefaultGuidesPerSecond = 2000.0;
constexpr double kInterpolateSeconds = 0.05, kShadeSeconds = 0.4, kReadCacheSeconds = 0.3;
constexpr double kConvertGlbSeconds = 3.0;  // a 50,000-strand coupe, .hair to .glb (issue 36)
// 150,000 strands of 65 points at 1920×1080, Samples 1 with shadows (issue 34): the whole command on a
// GPU and on a software rasteriser (llvmpipe, 2 cores), the passes on a GPU, a frame of a sequence on
// a GPU.
constexpr double kRenderCommandGpuSeconds = 0.3, kRenderCommandSoftwareSeconds = 2.0;
constexpr double kRenderPassesGpuSeconds = 0.005, kRenderFrameGpuSeconds = 0.1;
constexpr double kRenderPeakOverCache = 3.0;  // the command's peak memory over the cache's size
constexpr double kAnjyoFramesPerSecond = 200.0, kSpringsFramesPerSecond = 24.0;

// `done` things in `seconds` against a target of `perSecond` a second, `unit` naming them ("guides/s").
// Beside `of_target` the target itself is a counter, `target_` and its unit, which TargetTable reads.
void rateTarget(benchmark::State& state, double done, double seconds, double perSecond,
                const std::string& unit) {
  state.counters["of_target"] = done / seconds / perSecond;
  state.counters["target_" + unit] = perSecond;
}
// The iterations' `seconds` against a target of `target` seconds each.
void timeTarget(benchmark::State& state, double seconds, double target) {
  state.counters["of_target"] = target / (seconds / double(state.iterations()));
  state.counters["target_s"] = target;
}

// The sources (configs/) and the hairgen binary the benchmarks use: where they were built, or the
// environment's HAIRGEN_BENCH_SOURCE and HAIRGEN_BENCH_BINARY.
std::filesystem::path sourceDir() {
  const char* dir = std::getenv("HAIRGEN_BENCH_SOURCE");
  return dir && *dir ? dir : HAIRGEN_SOURCE_DIR;
}
std::string hairgenBinary() {
  const char* file = std::getenv("HAIRGEN_BENCH_BINARY");
  return file && *file ? file : HAIRGEN_BINARY;
}

// A bundled coupe's config and wick.
struct Bundled {
  Config config;
  Mesh wick;
  explicit Bundled(const char* setup)
      : config(loadConfig(sourceDir() / "configs" / setup, {}, SetupUse::kGrow)),
        wick(readObj(config.setup.wickModel.path)) {}
};
using Coupe3 = Bundled;

const Coupe3& coupe3() {
  static const Coupe3 c("thesis/coupe3/setup.txt");
  return c;
}
const Bundled& defaultCoupe() {
  static const Bundled c("default/setup.txt");
  return c;
}

void EnergyEvaluation(benchmark::State& state) {
  const Coupe3& c = coupe3();
  const size_t n = c.wick.vertexCount();
  std::vector<StrandEnergy> energies;
  std::vector<std::vector<double>> coordinates;
  for (size_t k = 0; k < 50; ++k) {
    size_t i = k * n / 50;
    RodFrame root = follicleFrame(glm::dvec3(c.wick.positions[i]), glm::dvec3(c.wick.normals[i]));
    energies.emplace_back(c.config.hairstyle, c.config.collision, root, double(k) / 50.0);
    coordinates.push_back(
        growGuide(root, double(k) / 50.0, c.config.hairstyle, c.config.collision).coordinates);
  }
  size_t k = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(energies[k](coordinates[k]));
    k = k + 1 == energies.size() ? 0 : k + 1;
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(EnergyEvaluation);

void growBundled(benchmark::State& state, const Bundled& c, double target,
                 Minimiser minimiser = Minimiser::kRosenbrock) {
  uint64_t evaluations = 0, guides = 0;
  Hairstyle style = c.config.hairstyle;
  style.minimiser = minimiser;
  Stopwatch clock;
  for (auto _ : state) {
    GrowResult g = grow(c.wick, style, c.config.collision, {});
    evaluations += g.evaluations;
    guides += g.reports.size();
  }
  state.counters["guides/s"] = benchmark::Counter(double(guides), benchmark::Counter::kIsRate);
  state.counters["evals/s"] = benchmark::Counter(double(evaluations), benchmark::Counter::kIsRate);
  state.counters["evals/s/core"] =
      benchmark::Counter(double(evaluations) / tbb::info::default_concurrency(), benchmark::Counter::kIsRate);
  state.counters["follicles"] = double(c.wick.vertexCount());
  state.counters["elements"] = double(c.config.hairstyle.hairLengths.size());
  rateTarget(state, double(guides), clock.lap(), target, "guides/s");
}
void GrowCoupe3(benchmark::State& state) {
  growBundled(state, coupe3(), kGrowCoupe3GuidesPerSecond);
}
BENCHMARK(GrowCoupe3)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(3.0);
void GrowDefault(benchmark::State& state) {
  growBundled(state, defaultCoupe(), kGrowDefaultGuidesPerSecond);
}
BENCHMARK(GrowDefault)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(3.0);
void GrowCoupe3Bfgs(benchmark::State& state) {
  growBundled(state, coupe3(), kGrowCoupe3GuidesPerSecond, Minimiser::kBfgs);
}
BENCHMARK(GrowCoupe3Bfgs)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(3.0);
void GrowDefaultBfgs(benchmark::State& state) {
  growBundled(state, defaultCoupe(), kGrowDefaultGuidesPerSecond, Minimiser::kBfgs);
}
BENCHMARK(GrowDefaultBfgs)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(3.0);

// Coupe 3's guides at 64 vertices and the style that gives ~150,000 strands from them.
struct Coupe3At150k {
  Hairstyle style;
  Strands guides;
  Coupe3At150k() : style(coupe3().config.hairstyle) {
    const Coupe3& c = coupe3();
    style.visualityStep = style.totalLength() / 63.0;  // 64 vertices per guide and strand
    guides = grow(c.wick, style, c.config.collision, {}).guides;
    style.hairDensity = 150000.0 / (surfaceArea(c.wick) * 1e4);
  }
};

// Interpolates coupe 3 at 150,000 strands once an iteration; `reuse` keeps one Strands across them.
void interpolateCoupe3(benchmark::State& state, bool reuse) {
  const Coupe3& c = coupe3();
  const Coupe3At150k in;
  uint64_t strands = 0, points = 0;
  Strands reused;
  if (reuse) interpolateInto(c.wick, in.guides, in.style, c.config.collision, {}, reused);  // its pages
  Stopwatch clock;
  for (auto _ : state) {
    Strands fresh;
    Strands& coupe = reuse ? reused : fresh;
    interpolateInto(c.wick, in.guides, in.style, c.config.collision, {}, coupe);
    strands += coupe.strandCount();
    points += coupe.pointCount();
    benchmark::DoNotOptimize(coupe.points.data());
  }
  state.counters["strands"] = double(strands) / double(state.iterations());
  state.counters["vertices/strand"] = double(points) / double(strands);
  state.counters["strands/s"] = benchmark::Counter(double(strands), benchmark::Counter::kIsRate);
  state.counters["vertices/s"] = benchmark::Counter(double(points), benchmark::Counter::kIsRate);
  timeTarget(state, clock.lap(), kInterpolateSeconds);
}
void InterpolateCoupe3(benchmark::State& state) {
  interpolateCoupe3(state, false);
}
BENCHMARK(InterpolateCoupe3)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(3.0);
void InterpolateCoupe3Frames(benchmark::State& state) {
  interpolateCoupe3(state, true);
}
BENCHMARK(InterpolateCoupe3Frames)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(3.0);

void ShadeCoupe3(benchmark::State& state) {
  const Coupe3& c = coupe3();
  Hairstyle style = c.config.hairstyle;
  style.visualityStep = style.totalLength() / 63.0;
  style.hairDensity = 150000.0 / (surfaceArea(c.wick) * 1e4);
  const Strands coupe =
      interpolate(c.wick, grow(c.wick, style, c.config.collision, {}).guides, style, c.config.collision, {});
  ShadeTimings total;
  glm::ivec3 grid(0);
  double shading = 0.0;
  ShadeResult r;
  for (auto _ : state) {
    // Neither the copy `shade` takes (hairgen shade moves its coupe in) nor freeing the last result
    // (~370 MB, ~25 ms; hairgen shade writes it and exits) is shade's work.
    state.PauseTiming();
    r = {};
    Strands input = coupe;
    state.ResumeTiming();
    Stopwatch clock;
    r = shade(std::move(input), c.config.visuality, c.config.render, {style.seed, ""});
    shading += clock.lap();
    total.volume += r.timings.volume;
    total.normals += r.timings.normals;
    grid = r.volume.density.size;
    benchmark::DoNotOptimize(r.coupe.normals.data());
  }
  const double n = double(state.iterations());
  state.counters["strands"] = double(coupe.strandCount());
  state.counters["vertices"] = double(coupe.pointCount());
  state.counters["grid_x"] = grid.x;
  state.counters["grid_y"] = grid.y;
  state.counters["grid_z"] = grid.z;
  state.counters["voxel_mm"] = c.config.render.voxelSize * 1000.0;
  state.counters["volume_s"] = total.volume / n;
  state.counters["normals_s"] = total.normals / n;
  timeTarget(state, shading, kShadeSeconds);
}
BENCHMARK(ShadeCoupe3)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(3.0);

// Anjyo's figures: 20,000 hairs of 20 segments on the head ellipsoid, styled as a cantilever beam.
struct AnjyoHairs {
  explicit AnjyoHairs(int count = 20000, int segments = 20);
  CollisionShape head{
      ShapeKind::kEllipsoid, 0.0, 10.0, glm::dvec3(-0.001, 0.068, 0.010), glm::dvec3(0.08, 0.08, 0.11),
      glm::dmat3(1.0),       {}};
  Mesh wick;
  Hairstyle style;
  Collision collision;
};

AnjyoHairs::AnjyoHairs(int count, int segments) {
  const int n = count;
  for (int i = 0; i < n; ++i) {
    double y = 1.0 - double(i) / (n - 1) * 1.2, r = std::sqrt(std::max(0.0, 1.0 - y * y)),
           phi = i * 2.399963229728653;
    glm::dvec3 unit(r * std::sin(phi), y, r * std::cos(phi));
    wick.positions.push_back(glm::vec3(head.centre + unit * head.halfExtents));
    wick.normals.push_back(glm::vec3(glm::normalize(unit / head.halfExtents)));
  }
  style.model = StylingModel::kCantilever;
  style.hairLengths = {0.22};
  style.segments = segments;
  style.forces.push_back(
      {glm::dvec3(6, 0, 0), ForceField::Region::kSide, 0.0, glm::dvec3(1, 0, 0), {}, {}, {}});
  collision.shapes.push_back(head);
}

void CantileverStyling(benchmark::State& state) {
  const AnjyoHairs hairs;
  for (auto _ : state)
    benchmark::DoNotOptimize(grow(hairs.wick, hairs.style, hairs.collision, {}).guides.points.data());
  state.counters["hairs/s"] = benchmark::Counter(
      double(hairs.wick.vertexCount()) * double(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(CantileverStyling)->Unit(benchmark::kMillisecond)->UseRealTime();

// Anjyo's dynamics on those 20,000 hairs of 20 segments through a second of the gust shot
// (configs/anjyo/gust: a side wind, one substep a frame, the paper's inertia, the pseudo-force field,
// collisions and joint limits) while the head turns, so the rotating frame's terms are computed too; frames/s
// is frames of the shot simulated per second of wall time (Anjyo reports 40 s a frame).
void SimulateAnjyo(benchmark::State& state) {
  const AnjyoHairs hairs;
  const Strands guides = grow(hairs.wick, hairs.style, hairs.collision, {}).guides;
  Config config;
  config.hairstyle = hairs.style;
  config.hairstyle.jointLimit = 40.0;
  config.hairstyle.jointLimitFrom = 3;
  config.collision = hairs.collision;
  config.dynamics.given = true;
  config.dynamics.firstFrame = 1;
  config.dynamics.lastFrame = 25;
  config.dynamics.wind = {{1, {-15.6, 0.0, 0.0}, false, {}},
                          {16, {-1.56, -19.6, 0.0}, false, {}}};  // the gust's
  HeadKey still, turned;
  still.frame = 1;
  turned.frame = 25;
  turned.rotation = {0.0, 40.0, 0.0};
  config.dynamics.headKeys = {still, turned};
  config.dynamics.substeps = 1;        // the gust shot's: 1 and 4 substeps look the same there
  config.dynamics.rootInertia = 20.0;  // its inertia, the paper's: Inertia 1 20 20
  config.dynamics.rootSegments = 20;
  SimulateOptions options;
  options.frames = {1, 25};
  size_t frames = 0;
  const std::clock_t start = std::clock();
  Stopwatch clock;
  for (auto _ : state)
    simulate(guides, config, options, [&](int, const Strands& g) {
      benchmark::DoNotOptimize(g.points.data());
      ++frames;
    });
  state.counters["frames/s"] = benchmark::Counter(double(frames), benchmark::Counter::kIsRate);
  state.counters["segments"] = double(guides.pointCount() - guides.strandCount());
  // As for SimulateSprings: CPU seconds of every thread per frame, what a shared machine's load leaves out.
  state.counters["cpu_s_per_frame"] = double(std::clock() - start) / CLOCKS_PER_SEC / double(frames);
  rateTarget(state, double(frames), clock.lap(), kAnjyoFramesPerSecond, "frames/s");
}
BENCHMARK(SimulateAnjyo)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(3.0);

// Model springs on 10,000 cantilever-styled hairs of 31 segments (32 particles) through a second of a
// 40° head turn with a side wind: 2 substeps a frame, damping 1/s, collisions with the head, velocity
// smoothing 0.3 a frame on a 1 cm grid. frames/s as for SimulateAnjyo (the issue asks for 24).
void SimulateSprings(benchmark::State& state) {
  const AnjyoHairs hairs(10000, 31);
  const Strands guides = grow(hairs.wick, hairs.style, hairs.collision, {}).guides;
  Config config;
  config.hairstyle = hairs.style;
  config.collision = hairs.collision;
  config.dynamics.given = true;
  config.dynamics.model = DynamicsModel::kSprings;
  config.dynamics.firstFrame = 1;
  config.dynamics.lastFrame = 25;
  config.dynamics.damping = 1.0;
  config.dynamics.substeps = 2;
  config.dynamics.velocitySmoothing = 0.3;
  config.dynamics.smoothingSpacing = 0.01;
  config.dynamics.wind = {{1, {-3.0, 0.0, 0.0}, false, {}}};
  HeadKey still, turned;
  still.frame = 1;
  turned.frame = 25;
  turned.rotation = {0.0, 40.0, 0.0};
  config.dynamics.headKeys = {still, turned};
  SimulateOptions options;
  options.frames = {1, 25};
  size_t frames = 0;
  const std::clock_t start = std::clock();
  Stopwatch clock;
  for (auto _ : state)
    simulate(guides, config, options, [&](int, const Strands& g) {
      benchmark::DoNotOptimize(g.points.data());
      ++frames;
    });
  state.counters["frames/s"] = benchmark::Counter(double(frames), benchmark::Counter::kIsRate);
  state.counters["particles"] = double(guides.pointCount());
  // CPU seconds of every thread per frame: on a shared machine the wall clock also counts the other
  // jobs' time, this does not (2 / cpu_s_per_frame is what 2 free cores would give at best).
  state.counters["cpu_s_per_frame"] = double(std::clock() - start) / CLOCKS_PER_SEC / double(frames);
  rateTarget(state, double(frames), clock.lap(), kSpringsFramesPerSecond, "frames/s");
}
BENCHMARK(SimulateSprings)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(3.0);

// Coupe 3 at about `strands` strands of `points` points each (64 for the caches', 65 for the render's,
// issue 34's figure), made once per size.
const Strands& coupe3Strands(int strands, int points = 64) {
  static std::map<std::pair<int, int>, Strands> made;
  auto it = made.find({strands, points});
  if (it != made.end()) return it->second;
  const Coupe3& c = coupe3();
  Hairstyle style = c.config.hairstyle;
  style.visualityStep = style.totalLength() / double(points - 1);
  const Strands guides = grow(c.wick, style, c.config.collision, {}).guides;
  const double area = surfaceArea(c.wick) * 1e4;
  style.hairDensity = strands / area;
  return made[{strands, points}] = interpolate(c.wick, guides, style, c.config.collision, {});
}

// The .hair cache of the 150,000-strand coupe (`points` a strand), written once, then read whole
// (checked: CRCs, finiteness).
std::filesystem::path coupeCache(int points = 64) {
  static std::map<int, std::filesystem::path> written;
  auto it = written.find(points);
  if (it != written.end()) return it->second;
  const std::filesystem::path f =
      std::filesystem::temp_directory_path() / ("hairgen_bench_coupe" + std::to_string(points) + ".hair");
  writeHair(f, coupe3Strands(150000, points));
  return written[points] = f;
}

void ReadCache(benchmark::State& state) {
  const std::filesystem::path file = coupeCache();
  Stopwatch clock;
  for (auto _ : state) {
    Strands s = readHair(file);
    benchmark::DoNotOptimize(s.points.data());
  }
  state.SetBytesProcessed(int64_t(state.iterations()) * int64_t(std::filesystem::file_size(file)));
  timeTarget(state, clock.lap(), kReadCacheSeconds);
}
BENCHMARK(ReadCache)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(3.0);

void WriteCache(benchmark::State& state) {
  const Strands& coupe = coupe3Strands(150000);
  const std::filesystem::path file = std::filesystem::temp_directory_path() / "hairgen_bench_write.hair";
  for (auto _ : state) writeHair(file, coupe);
  state.SetBytesProcessed(int64_t(state.iterations()) * int64_t(std::filesystem::file_size(file)));
  std::filesystem::remove(file);
}
BENCHMARK(WriteCache)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(3.0);

// `hairgen convert coupe.hair coupe.glb` of a coupe the size of the default one: read, then write.
void ConvertToGlb(benchmark::State& state) {
  const std::filesystem::path hair = std::filesystem::temp_directory_path() / "hairgen_bench_convert.hair";
  const std::filesystem::path glb = std::filesystem::temp_directory_path() / "hairgen_bench_convert.glb";
  writeHair(hair, coupe3Strands(50000));
  Stopwatch clock;
  for (auto _ : state) writeGltf(glb, readHair(hair), true);
  timeTarget(state, clock.lap(), kConvertGlbSeconds);
  state.SetBytesProcessed(int64_t(state.iterations()) * int64_t(std::filesystem::file_size(glb)));
  std::filesystem::remove(hair);
  std::filesystem::remove(glb);
}
BENCHMARK(ConvertToGlb)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(3.0);

// The render benchmarks' context, opened once (a sequence's, reused by every iteration), and whether it
// rasterises on the CPU (the targets differ).
bool benchContextOpened = false;
GlContext& benchContext() {
  static GlContext gl;
  benchContextOpened = true;
  return gl;
}
bool onGpu() {
  benchContext().makeCurrent();
  return !softwareRasteriser();
}
std::string deviceLabel() {
  GlContext& gl = benchContext();
  return gl.renderer() + " (" + gl.platform() + ")";
}
const Mesh& benchHead() {
  static const Mesh head = readObj(sourceDir() / "configs/assets/head.obj");
  return head;
}
constexpr int kRenderPoints = 65;  // a strand's points in the render benchmarks (issue 34)

// Coupe 3's Render Info at `width`×`height` and `samples` (shadows, the head, its camera and light).
RenderSettings benchSettings(int width, int height, int samples) {
  RenderSettings settings = coupe3().config.render;
  settings.resolution = {width, height};
  settings.samples = samples;
  return settings;
}

void Render(benchmark::State& state) {
  GlContext& gl = benchContext();
  const Strands& hair = coupe3Strands(int(state.range(0)), kRenderPoints);
  const RenderSettings settings =
      benchSettings(int(state.range(1)), int(state.range(2)), int(state.range(3)));
  RenderTimings sum;
  for (auto _ : state) {
    RenderOutput out = render(gl, hair, &benchHead(), coupe3().config.visuality, settings, {}, {});
    sum.upload += out.timings.upload;
    sum.lightDepth += out.timings.lightDepth;
    sum.opacity += out.timings.opacity;
    sum.shading += out.timings.shading;
    sum.readback += out.timings.readback;
  }
  const double n = double(state.iterations());
  const double passes = (sum.lightDepth + sum.opacity + sum.shading) / n;
  state.counters["strands"] = double(hair.strandCount());
  state.counters["upload_s"] = sum.upload / n;
  state.counters["lightDepth_s"] = sum.lightDepth / n;
  state.counters["opacity_s"] = sum.opacity / n;
  state.counters["shading_s"] = sum.shading / n;
  state.counters["passes_s"] = passes;
  state.counters["readback_s"] = sum.readback / n;
  state.SetLabel(deviceLabel());
  if (onGpu() && state.range(0) == 150000 && state.range(1) == 1920 && state.range(2) == 1080 &&
      state.range(3) == 1) {
    state.counters["of_target"] = kRenderPassesGpuSeconds / passes;
    state.counters["target_s"] = kRenderPassesGpuSeconds;
  }
}
BENCHMARK(Render)
    ->ArgNames({"strands", "width", "height", "samples"})
    ->Args({10000, 512, 512, 1})
    ->Args({10000, 512, 512, 4})
    ->Args({150000, 1920, 1080, 1})
    ->Args({150000, 1920, 1080, 4})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(3);

// The whole `hairgen render` command on the 150,000-strand coupe's cache at 1920×1080, Samples 1
// (reading the cache, the device's start, the passes, writing the EXR), run as a child process: its
// wall time against the target of the device this process opens (a GPU's or a software rasteriser's),
// and its peak memory (the child's maximum resident set) against 3× the cache's size (issues 20, 34).
void RenderCommand(benchmark::State& state) {
  const std::filesystem::path cache = coupeCache(kRenderPoints);
  const std::filesystem::path image = std::filesystem::temp_directory_path() / "hairgen_bench_render.exr";
  const std::string setup = (sourceDir() / "configs/thesis/coupe3/setup.txt").string();
  std::vector<std::string> args = {hairgenBinary(),
                                   "render",
                                   setup,
                                   "--hair",
                                   cache.string(),
                                   "--set",
                                   "Render.Resolution=1920 1080",
                                   "--set",
                                   "Render.Samples=1",
                                   "-q",
                                   "-o",
                                   image.string()};
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  long peakKiB = 0;
  const std::string label = deviceLabel();
  const double target = onGpu() ? kRenderCommandGpuSeconds : kRenderCommandSoftwareSeconds;
  Stopwatch clock;
  for (auto _ : state) {
    pid_t child = 0;
    if (posix_spawn(&child, argv[0], nullptr, nullptr, argv.data(), environ) != 0) {
      state.SkipWithError("could not start hairgen");
      return;
    }
    int status = 0;
    rusage usage{};
    pid_t waited;
    while ((waited = wait4(child, &status, 0, &usage)) < 0 && errno == EINTR) {
    }
    if (waited != child || !WIFEXITED(status) || WEXITSTATUS(status) != 0) {
      state.SkipWithError("hairgen render failed");
      return;
    }
    peakKiB = std::max(peakKiB, usage.ru_maxrss);
  }
  timeTarget(state, clock.lap(), target);
  state.SetLabel(label);
  std::filesystem::remove(image);
  const double peak = double(peakKiB) * 1024.0, cacheBytes = double(std::filesystem::file_size(cache));
  state.counters["peak_MB"] = peak / 1e6;
  state.counters["cache_MB"] = cacheBytes / 1e6;
  state.counters["peak_of_target"] = kRenderPeakOverCache * cacheBytes / peak;
  state.counters["peak_target_MB"] = kRenderPeakOverCache * cacheBytes / 1e6;
}
// One command an iteration; --benchmark_repetitions=5 gives the medians of five.
BENCHMARK(RenderCommand)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(1);

// A sequence of range(0) frames of the 150,000-strand coupe at 1920×1080, Samples 1, on one context as
// `render --frames` renders them: each frame's coupe is the last one moved by a tenth of a millimetre
// (done outside the timing), so nothing but the programs and buffers a context keeps carries over.
// frame_s is the median frame's seconds (the first frame, which compiles the programs, among them),
// frame_mean_s the mean.
void RenderSequence(benchmark::State& state) {
  GlContext& gl = benchContext();
  Strands hair = coupe3Strands(150000, kRenderPoints);
  const RenderSettings settings = benchSettings(1920, 1080, 1);
  const int frames = int(state.range(0));
  std::vector<double> seconds;
  for (auto _ : state) {
    for (int f = 0; f < frames; ++f) {
      state.PauseTiming();
      for (glm::vec3& p : hair.points) p.x += 1e-4f;
      state.ResumeTiming();
      Stopwatch clock;
      RenderOutput out = render(gl, hair, &benchHead(), coupe3().config.visuality, settings, {}, {});
      benchmark::DoNotOptimize(out.beauty.planes.data());
      seconds.push_back(clock.lap());
    }
  }
  double total = 0.0;
  for (double t : seconds) total += t;
  std::nth_element(seconds.begin(), seconds.begin() + std::ptrdiff_t(seconds.size() / 2), seconds.end());
  const double median = seconds[seconds.size() / 2];
  state.counters["frame_s"] = median;
  state.counters["frame_mean_s"] = total / double(seconds.size());
  state.SetLabel(deviceLabel());
  if (onGpu()) {
    state.counters["of_target"] = kRenderFrameGpuSeconds / median;
    state.counters["target_s"] = kRenderFrameGpuSeconds;
  }
}
BENCHMARK(RenderSequence)
    ->ArgName("frames")
    ->Arg(48)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(1);

// What `hairgen render` spends before its first pass: the EGL context opened (devices found, the
// display initialised, the context made) and a first render of one short strand at 8×8, which
// compiles and links every program it draws with (the head's too). A fresh context an iteration.
void DeviceStart(benchmark::State& state) {
  Strands strand;
  strand.addStrand({glm::vec3(0.0f, 0.0f, 0.0f), glm::vec3(0.01f, 0.0f, 0.0f)});
  const RenderSettings settings = benchSettings(8, 8, 1);
  GlStartTimes start;
  double opening = 0.0, first = 0.0;
  std::string label;
  for (auto _ : state) {
    Stopwatch clock;
    GlContext gl;
    opening += clock.lap();
    render(gl, strand, &benchHead(), coupe3().config.visuality, settings, {}, {});
    first += clock.lap();
    start.devices += gl.startTimes().devices;
    start.display += gl.startTimes().display;
    start.context += gl.startTimes().context;
    label = gl.renderer() + " (" + gl.platform() + ")" +
            (benchContextOpened ? ", the display already initialised by another benchmark's context" : "");
  }
  const double n = double(state.iterations());
  state.counters["open_s"] = opening / n;
  state.counters["devices_s"] = start.devices / n;
  state.counters["display_s"] = start.display / n;
  state.counters["context_s"] = start.context / n;
  state.counters["first_render_s"] = first / n;
  state.SetLabel(label);
  if (benchContextOpened) benchContext().makeCurrent();  // the other benchmarks' context, current again
}
BENCHMARK(DeviceStart)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(3);

// The beauty image's readback at 1920×1080 (issue 34): R G B A, Z, opacity and shadow from two
// RGBA32F textures as the resolve leaves them. pbo 0: what readBack did before (each texture whole
// through a pageable glGetTextureImage, then split into planes on one thread); readPlanes through a
// pixel-pack buffer, pbo 1 channel by channel (a GPU's layout), 2 whole textures (llvmpipe's).
void Readback(benchmark::State& state) {
  benchContext().makeCurrent();
  const int w = 1920, h = 1080;
  std::vector<float> texels(size_t(w) * h * 4);
  for (size_t i = 0; i < texels.size(); ++i) texels[i] = float(i % 1021) * 0.25f;
  const Texture color(GL_RGBA32F, w, h), data(GL_RGBA32F, w, h);
  for (const Texture* t : {&color, &data})
    glTextureSubImage2D(t->id, 0, 0, 0, w, h, GL_RGBA, GL_FLOAT, texels.data());
  glFinish();
  std::vector<std::vector<float>> planes(7);
  for (auto _ : state) {
    if (state.range(0) > 0) {
      std::vector<PlaneRead> reads;
      for (int c = 0; c < 4; ++c) reads.push_back({&color, c, &planes[size_t(c)]});
      for (int c = 0; c < 3; ++c) reads.push_back({&data, c, &planes[size_t(4 + c)]});
      readPlanes(reads, state.range(0) == 1 ? ReadbackLayout::kChannels : ReadbackLayout::kWholeTextures);
    } else {
      for (const Texture* t : {&color, &data}) {
        std::vector<float> rgba(size_t(w) * h * 4);
        glGetTextureImage(t->id, 0, GL_RGBA, GL_FLOAT, GLsizei(rgba.size() * sizeof(float)), rgba.data());
        const int first = t == &color ? 0 : 4, count = t == &color ? 4 : 3;
        for (int c = 0; c < count; ++c) {
          std::vector<float>& plane = planes[size_t(first + c)];
          plane.resize(size_t(w) * h);
          for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) plane[size_t(h - 1 - y) * w + x] = rgba[(size_t(y) * w + x) * 4 + c];
        }
      }
    }
    benchmark::DoNotOptimize(planes[6].data());
  }
  state.SetBytesProcessed(int64_t(state.iterations()) * 7 * w * h * int64_t(sizeof(float)));
  state.SetLabel(deviceLabel());
}
BENCHMARK(Readback)->ArgName("pbo")->DenseRange(0, 2)->Unit(benchmark::kMillisecond)->UseRealTime();

// After the benchmarks' own lines, every figure that has a target in one table: the figure, the target,
// the figure over the target and whether it is met (the README's Performance table gives the same
// figures with their history). A target is a pair of counters, `of_target` and `target_UNIT` (or
// `peak_of_target` and `peak_target_MB` for a second target of the same benchmark); with
// --benchmark_repetitions the medians are taken.
class TargetTable : public benchmark::ConsoleReporter {
 public:
  // As the library's own console (colour on a terminal; counters after the times, not as columns).
  TargetTable() : ConsoleReporter(isatty(STDOUT_FILENO) ? OO_Color : OO_None) {}
  void ReportRuns(const std::vector<Run>& runs) override {
    ConsoleReporter::ReportRuns(runs);
    for (const Run& run : runs) {
      if (run.error_occurred) continue;
      const bool aggregate = run.run_type == Run::RT_Aggregate;
      if (aggregate ? run.aggregate_name != "median" : run.repetitions > 1) continue;
      for (const auto& [key, ratio] : run.counters) {
        const size_t at = key.rfind("of_target");
        if (at == std::string::npos || at + 9 != key.size()) continue;
        const std::string prefix = key.substr(0, at) + "target_";
        const auto target = run.counters.lower_bound(prefix);
        if (target == run.counters.end() || target->first.compare(0, prefix.size(), prefix) != 0) continue;
        Row row;
        row.name = run.run_name.function_name + (run.run_name.args.empty() ? "" : "/" + run.run_name.args) +
                   (at > 0 ? " (" + key.substr(0, at - 1) + ")" : "");
        row.unit = target->first.substr(prefix.size());
        row.target = target->second.value;
        row.ratio = ratio.value;
        row.median = aggregate;
        rows_.push_back(row);
      }
    }
  }
  void Finalize() override {
    ConsoleReporter::Finalize();
    if (rows_.empty()) return;
    std::ostream& out = GetOutputStream();
    out << "\ntargets (issues 15, 16, 20):\n";
    out << "| benchmark | figure | target | of target | |\n|---|---|---|---|---|\n";
    for (const Row& r : rows_) {
      // A rate's figure is its target times the ratio; a time's or a size's, the target over it.
      const bool rate = r.unit.size() > 2 && r.unit.compare(r.unit.size() - 2, 2, "/s") == 0;
      // Seconds under a second are written in milliseconds.
      const double scale = r.unit == "s" && r.target < 1.0 ? 1000.0 : 1.0;
      const std::string unit = scale > 1.0 ? "ms" : r.unit;
      const double figure = rate ? r.ratio * r.target : r.target / r.ratio;
      out << "| " << r.name << " | " << number(figure * scale) << " " << unit << (r.median ? " (median)" : "")
          << " | " << number(r.target * scale) << " " << unit << " | " << number(r.ratio) << " | "
          << (r.ratio >= 1.0 ? "met" : "not met") << " |\n";
    }
  }

 private:
  struct Row {
    std::string name, unit;
    double target = 0.0, ratio = 0.0;
    bool median = false;
  };
  // Three significant figures, thousands apart with commas: 1,715, 0.427, 84.9.
  static std::string number(double v) {
    if (!std::isfinite(v)) return std::to_string(v);
    if (std::abs(v) >= 1000.0) {
      std::string digits = std::to_string(static_cast<long long>(std::llround(v)));
      for (int i = int(digits.size()) - 3; i > (digits[0] == '-' ? 1 : 0); i -= 3)
        digits.insert(size_t(i), ",");
      return digits;
    }
    char text[32];
    std::snprintf(text, sizeof text, "%.3g", v);
    return text;
  }
  std::vector<Row> rows_;
};

}  // namespace
}  // namespace hairgen

// BENCHMARK_MAIN's, with the table of targets after the console's lines (another --benchmark_format
// gets the library's own reporter and no table).
int main(int argc, char** argv) {
  bool console = true;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg.rfind("--benchmark_format=", 0) == 0 && arg != "--benchmark_format=console") console = false;
  }
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  if (console) {
    hairgen::TargetTable table;
    benchmark::RunSpecifiedBenchmarks(&table);
  } else {
    benchmark::RunSpecifiedBenchmarks();
  }
  benchmark::Shutdown();
  return 0;
}
