// Cost models of the stages. The constants are per-unit costs measured on the project's 2-core
// reference machine (`scripts/bench.sh`); an estimate is meant to be right within a factor of a few,
// which is all a refusal needs: the configs it stops are wrong by factors of thousands.
#include "stages/preflight/estimate.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <thread>

#include <tbb/blocked_range.h>
#include <tbb/global_control.h>
#include <tbb/parallel_reduce.h>
#include <tbb/task_arena.h>

#include "libcore/render/views.h"
#include "libcore/util/error.h"
#include "libcore/util/resources.h"
#include "libcore/util/text.h"
#include "libcore/volume/splat.h"

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
// The fewest strands hairCoverage gives a thread at once (its ranges split alike on any thread count).
constexpr size_t kCoverageGrain = 4096;
// The strands estimateRender measures the longest of on a thread at once.
constexpr size_t kLengthGrain = 4096;
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
// llvmpipe: per vertex pushed through a pass, and per fragment the ribbons cover (hairCoverage) with its
// shadow look-ups, at its most: fragments a depth test rejects cost less (coupe 3's 759 guides 0.1 m wide
// cover 4.3e9 sub-pixels of a 640x640 image in 12.8 s, 3 ns each; 0.02 m wide, 1.7e8 in 2.7 s).
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
  if (!e.impossible.empty()) throw InputError(e.impossible);
  const uint64_t budget = memoryBudget();
  if (e.bytes > budget)
    throw InputError(e.stage + " would need about " + formatBytes(e.bytes) + " of memory (" + e.detail +
                     "), more than the " + formatBytes(budget) + " free on this machine; change " +
                     e.memoryKey);
  if (!e.refusal.empty() && !force) throw InputError(e.refusal + ", or pass --force to run it anyway");
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
  // A .hair cache counts a strand's segments in 16 bits (cyHair's layout): a guide of more points could
  // be grown for minutes and then not written.
  constexpr size_t kMostPoints = 65536;
  if (const size_t points = pointsPerGuide(style); points > kMostPoints)
    e.impossible = "Hairstyle.VisualityStep " + formatReal(style.visualityStep) + " m over " +
                   formatReal(length) + " m of hair gives each guide " + std::to_string(points) +
                   " points; a .hair cache holds at most " + std::to_string(kMostPoints) +
                   " a strand: raise Hairstyle.VisualityStep";
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

namespace {

// A strand drawn wider than this share of the image's smaller side is a sheet, not a hair: 759 guides
// 0.5 m wide filled a 640x640 coupe image 400 times over (40 s of llvmpipe for a grey wall).
constexpr double kSheetShare = 0.25;

// What hairgen's rasteriser holds while it draws the camera's view at `block` × `block` sub-pixels,
// keeping `kept` fragments a sub-pixel, F of them in all (hairCoverage's KeptFragments), on `threads`
// threads, bytes; `points`, `segments`: the hair's. Each term is a buffer of camera_fragments.cpp
// or hair_raster.h:
//   slots       threads × kBandRows × W × (kept × kSlotBytes + kPixelRecordBytes): each thread's slots
//               for a band's sub-pixels and their records (W the sub-pixel image's width), alive until
//               the end;
//   words       2 × 12 × F: three words a fragment, gathered per band and then copied into one array
//               while the bands' are alive;
//   atlas       16 × F: the shading pass's two RGBA16F texels per kept fragment (host memory on
//               llvmpipe, the device's on a GPU);
//   per pixel   sub-pixels × 16: first, the counts, the tail and the head's depth read back;
//   bands       16 × points + 4 × segments: the quantised points and each segment listed in its band.
// The light's maps (their integers) are counted with the other light maps in renderCost. Against peak
// RSS on coupe 3 (150k strands of 65 points, 2 threads): 2.3 GB in all for 1.5 GB at 1920x1080 Samples 4,
// 5.7 GB for 3.1 GB with --reference at 480x270 (F 1.5-1.6 times the fragments kept).
double rasteriserBytes(const RenderSettings& r, int block, int kept, double fragments, size_t points,
                       size_t segments, size_t threads) {
  const double width = double(r.resolution.x) * block;
  const double fine = width * double(r.resolution.y) * block;
  const double slots =
      double(threads) * raster::kBandRows * width * (double(kept) * kSlotBytes + double(kPixelRecordBytes));
  return slots + fragments * (2.0 * 12.0 + 16.0) + fine * 16.0 + double(points) * 16.0 +
         double(segments) * 4.0;
}

// The render's memory and time, from `fragments`: the sub-pixel fragments the hair's ribbons cover, and
// `keptSeen`: those hairgen's rasteriser keeps, `kept` a sub-pixel (rasteriserBytes). `distance`: from
// the camera to the scene's centre, metres, where a strand's width is judged.
WorkEstimate renderCost(const RenderSettings& r, size_t strands, size_t points, size_t headTriangles,
                        double fragments, double keptSeen, int kept, double distance, int block) {
  WorkEstimate e;
  e.stage = "render";
  const double pixels = double(r.resolution.x) * double(r.resolution.y);
  const double fine = pixels * double(block) * double(block);
  const double keptAll = std::min(keptSeen, fine * kept);
  const int dom = std::clamp(std::max(r.resolution.x, r.resolution.y) / 2, 1024, 4096);
  // The shading targets (RGBA16F colour, RGBA32F data, 24-bit depth) at the sub-pixel resolution, the
  // resolved pair and the planes read back, the light's maps (textures, and the rasteriser's start
  // depth and four layer sums, 20 bytes a texel), and the hair and head on the device.
  const double framebuffers =
      fine * (8.0 + 16.0 + 4.0) + pixels * (32.0 + 7 * 4.0) + double(dom) * dom * (28.0 + 20.0);
  const double geometry = double(points) * 48.0 * 2.0 + double(strands) * 16.0 + double(headTriangles) * 36.0;
  // The threads the rasteriser draws bands on: this arena's, at most what --threads allows.
  const size_t threads = std::max<size_t>(
      1, std::min(size_t(tbb::this_task_arena::max_concurrency()),
                  tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism)));
  const double raster =
      rasteriserBytes(r, block, kept, keptAll, points, points - std::min(points, strands), threads);
  e.bytes = bytesOf(framebuffers + geometry + raster);
  e.memoryKey =
      framebuffers + raster >= geometry ? "Render.Resolution or Render.Samples" : "the coupe's size";
  e.seconds = 3.0 * double(points) * kSecondsPerVertex + (fragments + fine) * kSecondsPerFragment;
  const double focal = 0.5 * r.resolution.y / std::tan(0.5 * r.fieldOfView * M_PI / 180.0);
  const double widthPx = r.strandWidth * focal / std::max(distance, 1e-6);
  e.timeKey = widthPx > 4.0 ? "Render.StrandWidth" : "Render.Resolution or Render.Samples";
  e.detail = std::to_string(r.resolution.x) + "x" + std::to_string(r.resolution.y) + " pixels at " +
             std::to_string(block * block) + " samples, " + std::to_string(strands) + " strands, about " +
             formatReal(std::round(keptAll / 1e6)) + " million hair fragments kept";
  const double side = double(std::min(r.resolution.x, r.resolution.y));
  if (widthPx > kSheetShare * side)
    e.refusal = "Render.StrandWidth " + formatReal(r.strandWidth) + " m draws each strand about " +
                formatReal(std::round(widthPx)) + " pixels wide at the hair's distance, on a " +
                std::to_string(r.resolution.x) + "x" + std::to_string(r.resolution.y) +
                " image: a sheet, not a hair; lower Render.StrandWidth (a hair is 5e-05 to 0.0001 m wide)";
  return e;
}

// Metres to a tenth, for a strand's length in a message.
std::string tenths(double metres) {
  return formatReal(std::round(metres * 10.0) / 10.0);
}

// What a user with hair in other units is told to do, wherever the file is read: `render` reads a hair
// file in any unit it is told, `run` reads its Setup's LoadFile in metres.
constexpr const char* kGiveTheUnit =
    "give its unit (render --units cm, mm or in; for run's LoadFile, convert it first with "
    "convert --units)";

// Strands metres long are a file in other units (a groom in centimetres read as metres): say so, since
// no render setting is what is wrong.
void blameUnits(WorkEstimate& e, double hairLength) {
  if (hairLength > kLongestHairMetres)
    e.timeKey = "the hair's units: its strands are " + tenths(hairLength) +
                " m long, so the file is in other units: " + kGiveTheUnit;
}

// Liang-Barsky: clips the segment a + t (b − a), t in [t0, t1], to lo <= x, y <= hi; false when nothing
// is left.
bool clipToBox(const glm::dvec2& a, const glm::dvec2& b, const glm::dvec2& lo, const glm::dvec2& hi,
               double& t0, double& t1) {
  const glm::dvec2 d = b - a;
  for (int axis = 0; axis < 2; ++axis) {
    const double p[2] = {-d[axis], d[axis]}, q[2] = {a[axis] - lo[axis], hi[axis] - a[axis]};
    for (int side = 0; side < 2; ++side) {
      if (p[side] == 0.0) {
        if (q[side] < 0.0) return false;
        continue;
      }
      const double t = q[side] / p[side];
      if (p[side] < 0.0)
        t0 = std::max(t0, t);
      else
        t1 = std::min(t1, t);
      if (t0 > t1) return false;
    }
  }
  return true;
}

}  // namespace

double hairCoverage(const View& view, const Strands& hair, double strandWidth, double minWidthPx,
                    KeptFragments* kept) {
  const glm::dvec2 size(view.width, view.height);
  const double screen = size.x * size.y;
  const int tilesX = (view.width + kFootprintTile - 1) / kFootprintTile;
  const int tilesY = (view.height + kFootprintTile - 1) / kFootprintTile;
  const size_t tiles = kept ? size_t(tilesX) * size_t(tilesY) : 0;
  // The near plane (glm::perspective's), before which the device clips.
  const double nearDepth = std::max(view.proj[3][2] / (view.proj[2][2] - 1.0), 1e-9);
  // Strands in ranges split the same way whatever the thread count, and their sums added in the same
  // tree (parallel_deterministic_reduce): the same estimate on any number of threads, with a tile
  // array for only the ranges being summed at once.
  struct Sums {
    double fragments = 0.0;
    std::vector<double> given;  // the fragments given in each tile of kFootprintTile² pixels
  };
  // A point in the view: where it lies (x, y, and its depth along the view's −z), and where it is drawn
  // when it is in front of the near plane (each point's once, for both its segments).
  struct Seen {
    glm::dvec3 at;
    double depth;
    glm::dvec2 pixel{std::numeric_limits<double>::quiet_NaN()};   // on the image
    double trueWidth = std::numeric_limits<double>::quiet_NaN();  // the strand's width there, pixels
  };
  // Where a point in front of the near plane is drawn, from where it lies and its depth.
  auto draw = [&](Seen& q) {
    const double perDepth = view.focalPx / q.depth;
    q.pixel = 0.5 * size + perDepth * glm::dvec2(q.at.x, q.at.y);
    q.trueWidth = strandWidth * perDepth;
  };
  const glm::dmat4& m = view.view;
  auto seen = [&](uint32_t i) {
    const glm::dvec3 p(hair.points[i]);
    Seen q;
    q.at = glm::dvec3(m[0]) * p.x + glm::dvec3(m[1]) * p.y + glm::dvec3(m[2]) * p.z + glm::dvec3(m[3]);
    q.depth = -q.at.z;
    if (q.depth >= nearDepth) draw(q);
    return q;
  };
  // The segment a → b's part in front of the near plane, drawn: a point behind it moved onto it.
  auto onNearPlane = [&](const Seen& behind, const Seen& front) {
    Seen q;
    q.at = behind.at + (front.at - behind.at) * ((nearDepth - behind.depth) / (front.depth - behind.depth));
    q.depth = nearDepth;
    draw(q);
    return q;
  };
  // Strand s's segments added to `sums`.
  auto addStrand = [&](size_t s, Sums& sums) {
    if (hair.firstPoint[s] == hair.firstPoint[s + 1]) return;
    Seen next = seen(hair.firstPoint[s]);
    for (uint32_t i = hair.firstPoint[s]; i + 1 < hair.firstPoint[s + 1]; ++i) {
      Seen a = next, b = seen(i + 1);
      next = b;
      // The part of the segment in front of the eye.
      if (a.depth < nearDepth && b.depth < nearDepth) continue;
      if (a.depth < nearDepth)
        a = onNearPlane(a, b);
      else if (b.depth < nearDepth)
        b = onNearPlane(b, a);
      const double trueA = a.trueWidth, trueB = b.trueWidth;
      const double wa = std::max(trueA, minWidthPx), wb = std::max(trueB, minWidthPx);
      const glm::dvec2 pa = a.pixel, pb = b.pixel;
      // The ribbon reaches half its width beyond its centre line.
      const double reach = 0.5 * std::max(wa, wb);
      const glm::dvec2 lo(-reach), hi = size + reach;
      double t0 = 0.0, t1 = 1.0;
      const bool inside = glm::all(glm::greaterThanEqual(glm::min(pa, pb), lo)) &&
                          glm::all(glm::lessThanEqual(glm::max(pa, pb), hi));
      if (!inside && !clipToBox(pa, pb, lo, hi, t0, t1)) continue;
      const double length = glm::length(pb - pa) * (t1 - t0);
      const double width = wa + (wb - wa) * 0.5 * (t0 + t1);
      // A quad at least its width long (the joins), and never more than the image.
      sums.fragments += std::min(std::max(length, width) * width, screen);
      if (kept) {  // in the tile of the clipped segment's middle
        const glm::dvec2 middle = glm::clamp(pa + (pb - pa) * (0.5 * (t0 + t1)), glm::dvec2(0.0), size - 1.0);
        sums.given[size_t(middle.y / kFootprintTile) * size_t(tilesX) + size_t(middle.x / kFootprintTile)] +=
            std::min(length * (trueA + (trueB - trueA) * 0.5 * (t0 + t1) + 1.0), screen);
      }
    }
  };
  Sums total = tbb::parallel_deterministic_reduce(
      tbb::blocked_range<size_t>(0, hair.strandCount(), kCoverageGrain), Sums{},
      [&](const tbb::blocked_range<size_t>& range, Sums sums) {
        sums.given.resize(tiles, 0.0);
        for (size_t s = range.begin(); s < range.end(); ++s) addStrand(s, sums);
        return sums;
      },
      [](Sums a, const Sums& b) {
        a.fragments += b.fragments;
        a.given.resize(std::max(a.given.size(), b.given.size()), 0.0);
        for (size_t t = 0; t < b.given.size(); ++t) a.given[t] += b.given[t];
        return a;
      });
  const double fragments = total.fragments;
  std::vector<double> given = std::move(total.given);
  given.resize(tiles, 0.0);  // no strands: no range was summed
  if (kept) {
    kept->fragments = 0.0;
    for (int ty = 0; ty < tilesY; ++ty)
      for (int tx = 0; tx < tilesX; ++tx) {
        const double pixels = double(std::min(kFootprintTile, view.width - tx * kFootprintTile)) *
                              double(std::min(kFootprintTile, view.height - ty * kFootprintTile));
        kept->fragments += std::min(given[size_t(ty) * size_t(tilesX) + size_t(tx)], pixels * kept->perPixel);
      }
  }
  return fragments;
}

WorkEstimate estimateRender(const RenderSettings& r, const Strands& hair, const Mesh* head,
                            int maxTextureSize, int keptFragments) {
  const int block = subpixelBlock(r, maxTextureSize);
  const BoundingSphere sphere = boundingSphere(hair, head);
  const View fine = subpixelView(cameraView(r, sphere), block);
  KeptFragments kept{keptFragments};
  const double fragments = hairCoverage(fine, hair, r.strandWidth, double(block), &kept);
  WorkEstimate e =
      renderCost(r, hair.strandCount(), hair.pointCount(), head ? head->triangleCount() : 0, fragments,
                 kept.fragments, keptFragments, glm::length(sphere.centre - r.cameraPosition), block);
  // The longest strand (a maximum: the same whatever the thread count).
  const double longest = tbb::parallel_reduce(
      tbb::blocked_range<size_t>(0, hair.strandCount(), kLengthGrain), 0.0,
      [&](const tbb::blocked_range<size_t>& range, double most) {
        for (size_t s = range.begin(); s < range.end(); ++s) {
          double length = 0.0;
          for (uint32_t p = hair.firstPoint[s] + 1; p < hair.firstPoint[s + 1]; ++p)
            length += glm::length(glm::dvec3(hair.points[p]) - glm::dvec3(hair.points[p - 1]));
          most = std::max(most, length);
        }
        return most;
      },
      [](double x, double y) { return std::max(x, y); });
  blameUnits(e, longest);
  if (longest > kLongestHairMetres) {
    // How wide a strand is drawn at the hair's centre, in pixels (the sub-pixel view's focal length over
    // its k): said only where the camera is outside the hair, as the nearest strands are far wider.
    const double distance = glm::length(sphere.centre - r.cameraPosition);
    const std::string drawn =
        distance > sphere.radius
            ? ", and the strands are drawn " +
                  formatSignificant(r.strandWidth * fine.focalPx / double(block) / distance, 2) +
                  " pixels wide at the hair's centre (Render.StrandWidth " + formatReal(r.strandWidth) + " m)"
            : "";
    e.note = "the longest strand is " + tenths(longest) + " m" + drawn +
             ": if the hair file is not in metres, " + kGiveTheUnit;
  }
  return e;
}

WorkEstimate estimateRender(const RenderSettings& r, size_t strands, size_t points, size_t headTriangles,
                            double distance, double radius, double hairLength, int maxTextureSize,
                            int keptFragments) {
  const int block = subpixelBlock(r, maxTextureSize);
  const double fine = double(r.resolution.x) * r.resolution.y * block * block;
  // Each strand a ribbon at least a sub-pixel wide and as long as it looks from the scene's nearest
  // point, covering at most the image.
  const double nearest = std::max(distance - radius, 1e-3);
  const double focal = 0.5 * r.resolution.y * block / std::tan(0.5 * r.fieldOfView * M_PI / 180.0);
  const double scale = focal / nearest;
  const double widthPx = std::max(r.strandWidth * scale, double(block)), lengthPx = hairLength * scale;
  const double fragments = double(strands) * std::min(std::max(lengthPx, widthPx) * widthPx, fine);
  // Each strand's fragments: its length times its true width and one (KeptFragments), at most
  // keptFragments a sub-pixel (renderCost): for a coupe filling the image, the cap (default: 13 million
  // at 640x640 for 2.6 million kept, 1.1 GB in all for a 650 MB peak of `hairgen run`).
  const double keptSeen = double(strands) * lengthPx * (r.strandWidth * scale + 1.0);
  WorkEstimate e =
      renderCost(r, strands, points, headTriangles, fragments, keptSeen, keptFragments, distance, block);
  blameUnits(e, hairLength);
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
  // Rounded as interpolate's estimate says it, so the stages name the same count.
  const double strands = std::round(std::min(area * style.hairDensity + double(wick.triangleCount()), 1e18));
  const double coupePoints = std::min(strands * double(points), 1e18);
  // The hair reaches at most its length beyond the wick.
  const Bounds box = bounds(wick.positions);
  const glm::dvec3 span = glm::dvec3(box.max) - glm::dvec3(box.min) + 2.0 * length;
  if (shade) out.push_back(estimateShade(config.render, size_t(strands), size_t(coupePoints), span));
  if (render) {
    const glm::dvec3 centre = 0.5 * (glm::dvec3(box.min) + glm::dvec3(box.max));
    out.push_back(estimateRender(config.render, size_t(strands), size_t(coupePoints), 0,
                                 glm::length(config.render.cameraPosition - centre), 0.5 * glm::length(span),
                                 length, 16384));
  }
  return out;
}

std::vector<WorkEstimate> estimateShot(const Config& config, const Mesh& wick, bool shade, bool render,
                                       size_t threads) {
  if (!config.dynamics.given) return estimateRun(config, wick, shade, render, threads);
  const Dynamics& d = config.dynamics;
  const FrameRange frames{d.firstFrame, d.lastFrame};
  std::vector<WorkEstimate> out = estimateRun(config, wick, shade, false, threads);
  // The guides: one a wick vertex; their box reaches at most the hair's length beyond the wick.
  const size_t segments = wick.vertexCount() * (pointsPerGuide(config.hairstyle) - 1);
  const Bounds box = bounds(wick.positions);
  const glm::dvec3 span = glm::dvec3(box.max) - glm::dvec3(box.min) + 2.0 * config.hairstyle.totalLength();
  out.push_back(estimateSimulate(d, segments, frames, threads, span));
  out.back().frames = frames.count();
  // Each frame is interpolated and rendered as the rest coupe would be.
  for (WorkEstimate e : estimateRun(config, wick, false, render, threads)) {
    if (e.stage == "grow") continue;
    e.seconds *= double(frames.count());
    e.frames = frames.count();
    out.push_back(std::move(e));
  }
  return out;
}

}  // namespace hairgen
