// Cost models of the stages. The constants are per-unit costs measured on the project's 2-core
// reference machine (`scripts/bench.sh`); an estimate is meant to be right within a factor of a few,
// which is all a refusal needs: the configs it stops are wrong by factors of thousands.
#include "stages/estimate.h"

#include <algorithm>
#include <cmath>
#include <thread>

#include "libcore/util/error.h"
#include "libcore/util/resources.h"
#include "libcore/util/text.h"
#include "libcore/volume/hair_volume.h"

namespace hairgen {
namespace {

// Rosenbrock sweeps over the directions per stage: each stage goes on until every direction has had a
// success and a failure, which takes longer the more directions there are (measured on the default
// coupe: 2.6 sweeps at 4 elements; about 60 at 64 and 300 at 256).
double sweepsPerStage(double elements) {
  return 5.0 * std::max(1.0, elements / 4.0);
}
// One energy evaluation: per Super-Helix element (frame, closed forms) and per collision sample and
// shape (GrowCoupe3 benchmark: 1 µs for 4 elements, 32 samples and 2 shapes).
constexpr double kSecondsPerElement = 60e-9, kSecondsPerSample = 12e-9;
// Interpolation writes each point once with its tangent (InterpolateCoupe3: 150k × 64 in 0.2 s).
constexpr double kSecondsPerPoint = 25e-9;
// The volume: per grid node (sweeps, slides) and per splatted vertex (ShadeCoupe3: 800k nodes and 9.6M
// vertices in 1 s).
constexpr double kSecondsPerNode = 500e-9, kSecondsPerSplat = 60e-9;
// Anjyo's dynamics: one segment's step, with its trigonometry, joint limit and collision tests.
constexpr double kSecondsPerSegmentStep = 60e-9;
// Model springs: one particle's substep with the stretch solve, the banded solve and the collisions,
// and its share of the frame's velocity smoothing (SimulateSprings: ~0.12 CPU s a frame for 310k
// segments at 2 substeps).
constexpr double kSecondsPerSpringStep = 200e-9;
// Density targeting: per node of the eight grids of the level in use, per substep (configs/pixar/target
// at DensitySpacings 0.002: 16 substeps over 8 grids of ~5e6 nodes took 4.4 CPU s more than at 0.12).
constexpr double kSecondsPerDensityNode = 7e-9;
// llvmpipe: per vertex pushed through a pass, and per fragment of the shading pass with its shadow
// look-ups and overdraw (render benchmarks; 1,000 strands 0.5 m wide at 640x640 took 113 s).
constexpr double kSecondsPerVertex = 150e-9, kSecondsPerFragment = 60e-9;

double cores(size_t threads) {
  return double(std::max<size_t>(threads, 1));
}

std::string seconds(double s) {
  char text[32];
  if (s < 120)
    std::snprintf(text, sizeof text, "%.0f s", s);
  else if (s < 7200)
    std::snprintf(text, sizeof text, "%.0f minutes", s / 60);
  else if (s < 86400 * 3)
    std::snprintf(text, sizeof text, "%.0f hours", s / 3600);
  else
    std::snprintf(text, sizeof text, "%.3g days", s / 86400);
  return text;
}

// Saturating conversions: an estimate of 1e30 bytes is still a refusal, not a wrapped small number.
uint64_t bytesOf(double b) {
  return b >= 1.8e19 ? UINT64_MAX : uint64_t(std::max(b, 0.0));
}

}  // namespace

void requireFits(const WorkEstimate& e, bool force) {
  const uint64_t budget = memoryBudget();
  if (e.bytes > budget)
    throw InputError(e.stage + " would need about " + formatBytes(e.bytes) + " of memory (" + e.detail +
                     "), more than the " + formatBytes(budget) + " free on this machine; change " +
                     e.memoryKey);
  if (e.seconds > kTimeLimitSeconds && !force)
    throw InputError(e.stage + " would take about " + seconds(e.seconds) + " (" + e.detail + "); change " +
                     e.timeKey + ", or pass --force to run it anyway");
}

WorkEstimate estimateGrow(const Hairstyle& style, const Collision& collision, size_t follicles,
                          size_t threads) {
  WorkEstimate e;
  e.stage = "grow";
  const double length = style.totalLength();
  const double guides = double(follicles);
  if (style.model == StylingModel::kCantilever) {
    const double nodes = double(style.segments) + 1.0;
    e.bytes = bytesOf(guides * nodes * (24.0 + 48.0));     // the guides, and each hair's nodes in doubles
    e.seconds = guides * nodes * 200e-9 / cores(threads);  // a bend and a collision bisection per node
    e.memoryKey = e.timeKey = "Hairstyle.Segments";
    e.detail = formatReal(guides) + " hairs x " + formatReal(nodes) + " nodes";
    return e;
  }
  const double elements = double(style.hairLengths.size()), coordinates = 3.0 * elements;
  const double points = std::ceil(length / style.visualityStep) + 1.0;
  size_t shapes = 0;
  for (const CollisionShape& s : collision.shapes) shapes += s.penalty > 0.0;
  const double samples = shapes ? std::ceil(length / style.collisionStep) : 0.0;
  // The guides (points and tangents); per thread the samples' arc lengths and a guide in doubles.
  const double output = guides * points * 24.0, scratch = cores(threads) * (samples * 8.0 + points * 56.0);
  e.bytes = bytesOf(output + scratch + guides * coordinates * 8.0);
  e.memoryKey = output >= scratch ? "Hairstyle.VisualityStep" : "Hairstyle.CollisionStep";
  const double perEvaluation =
      kSecondsPerElement * elements + kSecondsPerSample * samples * double(shapes) + 1e-9 * coordinates;
  // Rosenbrock: MaxIter stages of sweeps over every coordinate. BFGS: what it takes in practice, up to
  // 200 values with gradients a guide (17-142 on the bundled coupes, 36 at 256 elements), each costing 2.5
  // values whatever the coordinates (one walk up the rod and one back: 2.3 at 4 elements, 1.7 at 256)
  // and the update of the dense inverse Hessian, 4 ns per entry (2.4 ms at 768 coordinates).
  if (style.minimiser == Minimiser::kBfgs) {
    const double bound = 2.0 * double(style.maxIter) * coordinates + 40.0;  // quasi_newton's
    const double evaluations = std::min(bound, 200.0);
    e.seconds =
        guides * evaluations * (2.5 * perEvaluation + 4e-9 * coordinates * coordinates) / cores(threads);
  } else {
    const double evaluations = double(style.maxIter) * sweepsPerStage(elements) * coordinates;
    e.seconds = guides * evaluations * perEvaluation / cores(threads);
  }
  e.timeKey = kSecondsPerSample * samples * double(shapes) > kSecondsPerElement * elements
                  ? "Hairstyle.CollisionStep"
                  : "Hairstyle.HairLengths (fewer Super-Helix elements) or Hairstyle.MaxIter";
  e.detail = formatReal(guides) + " guides of " + formatReal(elements) + " elements, " + formatReal(points) +
             " points and " + formatReal(samples) + " collision samples each";
  return e;
}

WorkEstimate estimateInterpolate(const Hairstyle& style, double wickAreaCm2, size_t triangles,
                                 size_t pointsPerGuide) {
  WorkEstimate e;
  e.stage = "interpolate";
  const double strands = wickAreaCm2 * style.hairDensity + double(triangles);  // + the rounding up
  const double points = strands * double(pointsPerGuide);
  // Points and tangents, and per strand its id, root, guides and weights.
  e.bytes = bytesOf(points * 24.0 + strands * 64.0);
  e.seconds = points * kSecondsPerPoint;
  // Many points per strand come from the guides' sampling, not from the density.
  const char* sampling =
      style.model == StylingModel::kCantilever ? "Hairstyle.Segments" : "Hairstyle.VisualityStep";
  e.memoryKey = e.timeKey =
      pointsPerGuide > 1000 ? std::string(sampling) + " or Hairstyle.HairDensity" : "Hairstyle.HairDensity";
  e.detail = formatReal(std::round(strands)) + " strands of " + std::to_string(pointsPerGuide) + " points";
  return e;
}

WorkEstimate estimateShade(const RenderSettings& render, size_t strands, size_t points,
                           const glm::dvec3& span) {
  WorkEstimate e;
  e.stage = "shade";
  const glm::dvec3 nodes = glm::ceil(span / render.voxelSize) + 1.0 + 2.0 * double(render.volumePadding);
  const double grid = nodes.x * nodes.y * nodes.z;
  // Per node: density, smoothed density and distance (floats), gradients and nearest shell points
  // (float triples), the sweep's state; per vertex its normal, and the coupe itself.
  // The splat's per-thread grids (int64 per node), as many as kSplatCopiesBytes holds and the cores use.
  const double copies = std::min(grid * 8.0 * double(std::max(1u, std::thread::hardware_concurrency())),
                                 std::max(kSplatCopiesBytes, grid * 8.0));
  e.bytes = bytesOf(grid * 64.0 + copies + double(points) * (12.0 + 40.0) + double(strands) * 64.0);
  e.seconds = grid * kSecondsPerNode + double(points) * kSecondsPerSplat;
  e.memoryKey = e.timeKey = "Render.VoxelSize (or check the cache is in metres)";
  e.detail = formatReal(nodes.x) + " x " + formatReal(nodes.y) + " x " + formatReal(nodes.z) + " grid nodes";
  return e;
}

WorkEstimate estimateRender(const RenderSettings& r, size_t strands, size_t points, size_t headTriangles,
                            double nearest, double hairLength, int maxTextureSize) {
  WorkEstimate e;
  e.stage = "render";
  int block = std::clamp(int(std::lround(std::sqrt(double(r.samples)))), 1, 8);
  while (block > 1 && std::max(r.resolution.x, r.resolution.y) * block > maxTextureSize) --block;
  const double pixels = double(r.resolution.x) * double(r.resolution.y);
  const double fine = pixels * double(block) * double(block);
  const int dom = std::clamp(std::max(r.resolution.x, r.resolution.y) / 2, 1024, 4096);
  // The shading targets (RGBA16F colour, RGBA32F data, 24-bit depth) at the sub-pixel resolution, the
  // resolved pair and the planes read back, the light's maps, and the hair and head on the device.
  const double framebuffers =
      fine * (8.0 + 16.0 + 4.0) + pixels * (32.0 + 7 * 4.0) + double(dom) * dom * 28.0;
  const double geometry = double(points) * 48.0 * 2.0 + double(strands) * 16.0 + double(headTriangles) * 36.0;
  e.bytes = bytesOf(framebuffers + geometry);
  e.memoryKey = framebuffers >= geometry ? "Render.Resolution or Render.Samples" : "the coupe's size";
  // Fill: each strand is a ribbon at least a sub-pixel wide and as long as it looks from the nearest
  // point of the scene.
  const double focal = 0.5 * r.resolution.y * block / std::tan(0.5 * r.fieldOfView * M_PI / 180.0);
  const double scale = focal / std::max(nearest, 1e-3);
  const double widthPx = std::max(r.strandWidth * scale, double(block)), lengthPx = hairLength * scale;
  const double fragments = double(strands) * lengthPx * widthPx + fine;
  e.seconds = 3.0 * double(points) * kSecondsPerVertex + fragments * kSecondsPerFragment;
  e.timeKey = widthPx > 4.0 * block ? "Render.StrandWidth" : "Render.Resolution or Render.Samples";
  // Strands metres long are a file in other units (a groom in centimetres read as metres): say so, since
  // no render setting is what is wrong.
  if (hairLength > 3.0)
    e.timeKey = "the hair's units: its strands are " + formatReal(std::round(hairLength * 10.0) / 10.0) +
                " m long, so the file is in other units (render it with --units cm or mm, or --frame)";
  e.detail = std::to_string(r.resolution.x) + "x" + std::to_string(r.resolution.y) + " pixels at " +
             std::to_string(block * block) + " samples, " + std::to_string(strands) + " strands";
  return e;
}

WorkEstimate estimateSimulate(const Dynamics& d, size_t segments, const FrameRange& frames, size_t threads,
                              const glm::dvec3& span) {
  WorkEstimate e;
  e.stage = "simulate";
  const double steps = double(frames.count()) * double(d.substeps);
  // Per segment: state, rest, constants and a posed copy. Model springs keeps more (bytes): positions,
  // velocities and rest points in doubles 72, per-point constants (eight numbers and the bending target)
  // and the factored matrix 112, rest directions and tangents 36, a collision shape's rest depths 8,
  // the vector kernel's lane-by-lane copy of its constants 112, the smoothing's point lists 120, the
  // posed copy and the restart state 72.
  const bool springs = d.model == DynamicsModel::kSprings;
  const double hair = double(segments) * (springs ? 532.0 : 200.0);
  // Model springs' grids over the hair (and the target): per density spacing eight float grids of the
  // target, and at the finest two sets of eight more (the substep's D_s − D_t and the level choice's);
  // the velocity grid (dvec4 nodes, at most kMaxGridNodes of spring_dynamics.cpp) and its splat lists.
  auto nodes = [&](double h, double padding) {
    const glm::dvec3 n = glm::ceil(span / h) + 1.0 + 2.0 * padding;
    return n.x * n.y * n.z;
  };
  double density = 0.0, finest = 0.0;
  if (springs && d.densityTarget.given())
    for (double h : d.densitySpacings) {
      density += 8.0 * 4.0 * nodes(h, 3.5);
      finest = std::max(finest, nodes(h, 3.5));
    }
  density += 2.0 * 8.0 * 4.0 * finest;
  const double smoothing =
      springs && d.velocitySmoothing > 0.0 ? 2.0 * 32.0 * std::min(nodes(d.smoothingSpacing, 1.5), 2e7) : 0.0;
  e.bytes = bytesOf(hair + density + smoothing);
  const double perStep = springs ? kSecondsPerSpringStep : kSecondsPerSegmentStep;
  const double hairSeconds = double(segments) * steps * perStep / cores(threads);
  // Every substep with a target copies and negates the eight grids of D_t at its level and splats the
  // hair into them, on one core.
  const double densitySeconds = steps * 8.0 * finest * kSecondsPerDensityNode;
  e.seconds = hairSeconds + densitySeconds;
  e.memoryKey = density > hair + smoothing ? "Dynamics.DensitySpacings (its finest spacing, in metres)"
                                           : "the guides' size";
  e.timeKey = densitySeconds > hairSeconds ? "Dynamics.DensitySpacings (its finest spacing, in metres)"
                                           : "Dynamics.Substeps or Dynamics.Frames";
  e.detail = std::to_string(segments) + " segments, " + formatReal(steps) + " steps";
  if (density > 0.0)
    e.detail += ", density grids of " + formatReal(std::round(finest)) + " nodes at the finest spacing";
  return e;
}

size_t pointsPerGuide(const Hairstyle& style) {
  if (style.model == StylingModel::kCantilever) return size_t(style.segments) + 1;
  const double points = std::ceil(style.totalLength() / style.visualityStep) + 1.0;
  return points < 1e15 ? size_t(points) : size_t(1e15);
}

std::vector<WorkEstimate> estimateRun(const Config& config, const Mesh& wick, bool shade, bool render,
                                      size_t threads) {
  const Hairstyle& style = config.hairstyle;
  const double area = surfaceArea(wick) * 1e4, length = style.totalLength();
  const size_t points = pointsPerGuide(style);
  std::vector<WorkEstimate> out = {estimateGrow(style, config.collision, wick.vertexCount(), threads),
                                   estimateInterpolate(style, area, wick.triangleCount(), points)};
  const double strands = std::min(area * style.hairDensity + double(wick.triangleCount()), 1e18);
  const double coupePoints = std::min(strands * double(points), 1e18);
  // The hair reaches at most its length beyond the wick.
  const Bounds box = bounds(wick.positions);
  const glm::dvec3 span = glm::dvec3(box.max) - glm::dvec3(box.min) + 2.0 * length;
  if (shade) out.push_back(estimateShade(config.render, size_t(strands), size_t(coupePoints), span));
  if (render) {
    const glm::dvec3 centre = 0.5 * (glm::dvec3(box.min) + glm::dvec3(box.max));
    const double nearest = glm::length(config.render.cameraPosition - centre) - 0.5 * glm::length(span);
    out.push_back(estimateRender(config.render, size_t(strands), size_t(coupePoints), 0,
                                 std::max(nearest, 1e-3), length, 16384));
  }
  return out;
}

}  // namespace hairgen
