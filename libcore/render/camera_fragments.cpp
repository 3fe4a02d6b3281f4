#include "libcore/render/camera_fragments.h"

#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <limits>
#include <memory>
#include <string>

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_pipeline.h>
#include <tbb/task_arena.h>

#include "libcore/render/hair_raster.h"
#include "libcore/util/error.h"
#include "libcore/util/uninitialised.h"

namespace hairgen {

namespace {

// The most fragments the words are reserved for at once (1.5 GB of address space, none of it the
// process's until written): more grow as a vector grows.
constexpr uint64_t kMostReserved = uint64_t(1) << 27;

// A kept fragment while its band is drawn.
struct Slot {
  int32_t depth;      // kDepthUnit: its nearest piece's
  uint32_t origin;    // its first piece's segment (its first point), which orders equal depths
  uint32_t point;     // the segment of its largest piece, where it is shaded
  uint32_t last;      // the last segment merged into it
  uint32_t coverage;  // kCoverageOne per pixel, all its pieces'
  uint32_t largest;   // its largest piece's coverage
  uint32_t span;      // where its largest piece lies along its segment, 1/kSpanUnit
  bool nearer(const Slot& o) const { return depth != o.depth ? depth < o.depth : origin < o.origin; }
};
static_assert(sizeof(Slot) == kSlotBytes);

// A depth in kDepthUnit as the metres it is stored and compared as (a float: the blend reads it so).
float metresOf(int32_t depth) {
  return float(double(depth) * kDepthUnit);
}

uint32_t spanOf(raster::Piece piece) {
  return uint32_t(piece.twice * int64_t(kSpanUnit) / (2 * piece.length));
}

// What a pixel's keep() reads for every piece, apart from its kept fragments: a band's pixels' records
// hold in the cache where their fragments do not (28 bytes × kept a pixel: 14 MB a band at 1920 pixels
// a row).
struct Pixel {
  // The depth of the farthest kept fragment when the pixel keeps all it can, INT32_MAX before: a piece
  // farther than that goes to the tail without a look at the fragments (most pieces in thick hair: 36
  // million of the 1080p coupe's 51 million; looking cost a cache miss each).
  int32_t farthest;
  uint32_t touched;  // the last segment whose piece reached the pixel
  uint32_t tail;     // the coverage behind the kept fragments
  uint32_t n;        // fragments kept
};
static_assert(sizeof(Pixel) == kPixelRecordBytes);

// One pixel's kept fragments, `pixel.n` of `kept`, nearest first.
void keep(Slot* list, Pixel& pixel, int kept, int32_t depth, uint32_t coverage, uint32_t point,
          raster::Piece piece) {
  // Segments come in the order of their first point, so a piece of the same strand from the same
  // segment or the one before merges into its fragment (points are one strand's when one apart: a
  // segment joins a point to the next of its strand). No fragment's last segment is later than
  // `touched`, the last whose piece reached the pixel, so when that is older than the one before this
  // one, none is looked at (most pieces in thick hair: 8% of the camera's fragments' time).
  const bool mergeable = point - pixel.touched <= 1;
  pixel.touched = point;
  uint32_t n = pixel.n;
  auto farthestKept = [&] { return n == uint32_t(kept) ? list[n - 1].depth : INT32_MAX; };
  for (uint32_t k = 0; mergeable && k < n; ++k) {
    Slot& s = list[k];
    if (point - s.last > 1) continue;
    raster::addSaturating(s.coverage, coverage);
    s.last = point;
    if (coverage > s.largest) {  // shaded where most of it is
      s.largest = coverage;
      s.point = point;
      s.span = spanOf(piece);
    }
    if (depth < s.depth) {
      s.depth = depth;
      for (uint32_t j = k; j > 0 && list[j].nearer(list[j - 1]); --j) std::swap(list[j], list[j - 1]);
      pixel.farthest = farthestKept();
    }
    return;
  }
  const Slot fresh{depth, point, point, point, coverage, coverage, 0};
  if (n == uint32_t(kept)) {
    // Not nearer than the farthest kept (Slot::nearer, its origin read only for a tie).
    if (depth > pixel.farthest || (depth == pixel.farthest && !fresh.nearer(list[n - 1]))) {
      raster::addSaturating(pixel.tail, coverage);
      return;
    }
    raster::addSaturating(pixel.tail, list[--n].coverage);
  }
  uint32_t j = n++;
  for (; j > 0 && fresh.nearer(list[j - 1]); --j) list[j] = list[j - 1];
  list[j] = fresh;
  list[j].span = spanOf(piece);
  pixel.n = n;
  pixel.farthest = farthestKept();
}

// What hides the hair, by tiles of kTile × kTile pixels: a segment all of whose fragments are as deep
// as the deepest opaque depth over the pixels it can reach has no fragment keep() would get (each
// fragment's depth lies between its segment's points' depths, and metresOf keeps the order), so it is
// not drawn. The head hides the back of the hair: a third of the camera's fragments.
class Hidden {
 public:
  Hidden(const float* opaque, int width, int height)
      : columns_((width + kTile - 1) / kTile),
        rows_((height + kTile - 1) / kTile),
        width_(width),
        height_(height) {
    if (!opaque) return;
    deepest_.assign(size_t(columns_) * size_t(rows_), -std::numeric_limits<float>::infinity());
    tbb::parallel_for(0, rows_, [&](int ty) {
      for (int y = ty * kTile; y < std::min(height, (ty + 1) * kTile); ++y)
        for (int x = 0; x < width; ++x) {
          const float d = opaque[size_t(y) * size_t(width) + size_t(x)];
          float& m = deepest_[size_t(ty) * size_t(columns_) + size_t(x / kTile)];
          m = std::isnan(d) ? std::numeric_limits<float>::infinity() : std::max(m, d);
        }
    });
  }
  bool behind(const raster::Vertex& a, const raster::Vertex& b) const {
    if (deepest_.empty()) return false;
    const float nearest = metresOf(std::min(a.depth, b.depth));
    const int64_t reach = raster::segmentReach(a, b);
    auto tiles = [&](int64_t lo, int64_t hi, int pixels, int& first, int& last) {
      first = int(std::max<int64_t>(0, raster::floorDiv(lo - reach, kSubTexel))) / kTile;
      last = int(std::min<int64_t>(pixels - 1, raster::floorDiv(hi + reach, kSubTexel))) / kTile;
    };
    int x0, x1, y0, y1;
    tiles(std::min(a.x, b.x), std::max(a.x, b.x), width_, x0, x1);
    tiles(std::min(a.y, b.y), std::max(a.y, b.y), height_, y0, y1);
    for (int ty = y0; ty <= y1; ++ty)
      for (int tx = x0; tx <= x1; ++tx)
        if (!(nearest >= deepest_[size_t(ty) * size_t(columns_) + size_t(tx)])) return false;
    return true;  // also where it reaches no pixel: it has no fragment
  }

 private:
  static constexpr int kTile = 8;  // pixels a side
  int columns_, rows_, width_, height_;
  std::vector<float> deepest_;  // per tile, the largest opaque depth (+∞ for a NaN), metres
};

}  // namespace

CameraFragments rasteriseCameraFragments(const Strands& hair, const View& camera, double strandWidth,
                                         int kept, const float* opaque) {
  return cameraFragments(raster::projectIntoBands(hair, camera, strandWidth), kept, opaque);
}

void requireShadable(uint64_t fragments, uint64_t limit) {
  if (fragments > limit)
    throw InputError("the camera sees more than " + std::to_string(limit) +
                     " hair fragments, more than the renderer can shade at once; lower Render.Samples or "
                     "Render.Resolution");
}

CameraFragments cameraFragments(const raster::Bands& bands, int kept, const float* opaque, uint64_t limit) {
  kept = std::clamp(kept, 1, 255);                // as the device's passes take it (compute_raster.cpp)
  limit = std::min<uint64_t>(limit, UINT32_MAX);  // what `first` indexes
  std::atomic<uint64_t> keptSoFar{0};             // the fragments of the bands drawn so far
  const size_t width = size_t(bands.width), pixels = width * size_t(bands.height);
  CameraFragments out;
  out.width = bands.width;
  out.height = bands.height;
  out.tail.assign(pixels, 0);
  // Each pixel's count of kept fragments, then (summed in order) its first fragment.
  out.first.resize(pixels + 1);
  // A band's pixels' slots, one set a thread, reused from band to band (a band's are ~14 MB at 1920
  // pixels a row: allocated for each band, their pages were cleared again each time).
  struct BandSlots {
    std::vector<Slot> slots;
    std::vector<Pixel> pixels;
  };
  tbb::enumerable_thread_specific<BandSlots> perThread;
  const Hidden hidden(opaque, bands.width, bands.height);
  using Words = std::vector<uint32_t, UninitialisedAllocator<uint32_t>>;
  // Band b's words: its pixels' kept fragments in order.
  auto drawBand = [&](int band) {
    const size_t base = size_t(band) * raster::kBandRows * width;
    const size_t end = std::min(pixels, base + raster::kBandRows * width);
    BandSlots& mine = perThread.local();
    mine.slots.resize((end - base) * size_t(kept));
    // `touched` is set by a pixel's first keep() in the band, which merges nothing.
    mine.pixels.assign(end - base, Pixel{INT32_MAX, 0, 0, 0});
    std::vector<Slot>& slots = mine.slots;
    std::vector<Pixel>& records = mine.pixels;
    bands.eachFragment<raster::Across::kBox>(
        band,
        [&](size_t texel, int32_t depth, uint32_t coverage, uint32_t point, raster::Piece piece) {
          // Compared as the blend compares them: the fragment's depth as the float it is stored as.
          if (opaque && metresOf(depth) >= opaque[texel]) return;
          const size_t local = texel - base;
          keep(&slots[local * size_t(kept)], records[local], kept, depth, coverage, point, piece);
        },
        [&](const raster::Vertex& a, const raster::Vertex& b) { return hidden.behind(a, b); });
    size_t count = 0;
    for (const Pixel& p : records) count += p.n;
    requireShadable(keptSoFar.fetch_add(count) + count, limit);
    auto words = std::make_unique<Words>(3 * count);
    uint32_t* word = words->data();
    for (size_t p = 0; p < end - base; ++p) {
      out.first[base + p] = records[p].n;
      out.tail[base + p] = records[p].tail;
      for (uint32_t k = 0; k < records[p].n; ++k, word += 3) {
        const Slot& s = slots[p * size_t(kept) + size_t(k)];
        word[0] = s.point;
        word[1] = std::bit_cast<uint32_t>(metresOf(s.depth));
        word[2] = std::min(s.coverage, kCoverageOne) | (s.span << kCoverageBits);
      }
    }
    return words;
  };
  // The bands drawn on every thread, a few at a time, each band's words put after the last's as soon
  // as it and the bands before it are done, and freed: only the bands in flight are held twice. (Drawn
  // all at once and joined after, every band's words and the joined copy were held at the end: the
  // 1080p coupe's camera fragments peaked 29 MiB higher.) `words` is reserved for the most its pixels
  // can keep, or `limit`: pages untouched are not the process's, and no join copies it again.
  out.words.reserve(3 * size_t(std::min<uint64_t>({uint64_t(kept) * pixels, limit, kMostReserved})));
  int next = 0;
  tbb::parallel_pipeline(
      size_t(2 * tbb::this_task_arena::max_concurrency()),
      tbb::make_filter<void, int>(tbb::filter_mode::serial_in_order,
                                  [&](tbb::flow_control& control) {
                                    if (next == bands.count) control.stop();
                                    return next++;
                                  }) &
          tbb::make_filter<int, std::unique_ptr<Words>>(tbb::filter_mode::parallel, drawBand) &
          tbb::make_filter<std::unique_ptr<Words>, void>(
              tbb::filter_mode::serial_in_order, [&](std::unique_ptr<Words> words) {
                out.words.insert(out.words.end(), words->begin(), words->end());
              }));
  uint32_t total = 0;  // at most `limit`
  for (size_t p = 0; p < pixels; ++p) {
    const uint32_t n = out.first[p];
    out.first[p] = total;
    total += n;
  }
  out.first[pixels] = total;
  return out;
}

}  // namespace hairgen
