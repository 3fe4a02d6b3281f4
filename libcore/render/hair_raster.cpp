#include "libcore/render/hair_raster.h"

#include <algorithm>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "libcore/util/huge_pages.h"

namespace hairgen::raster {

namespace {

constexpr size_t kBinChunk = size_t(1) << 14;  // points, or segments, a thread handles at once
// A point this many image widths off the image is dropped with its segments: what it could reach of
// the image is a ribbon the view's field already holds whole (it is made to hold the scene's sphere).
constexpr int64_t kFarOff = 4;
// The widest strand drawn, texels: wider is drawn this wide. With points within kFarOff image widths of
// an image of at most 2^15 texels (OpenGL's largest), a segment is shorter than 2^27 in 1/kSubTexel, so
// width × length × a piece's length stays below 2^28 · 2^27 · 2^8 = 2^63: every product fits 64 bits.
constexpr double kWidest = 4096.0;

// std::lround's answer (halves away from zero) for |x| < 2^31, inline: libm's call was a tenth of a
// second of the 1080p coupe's two projections. The truncation and the remainder are exact.
constexpr int32_t rounded(double x) {
  int64_t i = int64_t(x);
  const double rest = x - double(i);
  if (rest >= 0.5) ++i;
  if (rest <= -0.5) --i;
  return int32_t(i);
}
static_assert(rounded(0.5) == 1 && rounded(-0.5) == -1 && rounded(1.5) == 2 && rounded(-1.5) == -2 &&
              rounded(2.5) == 3 && rounded(-2.5) == -3 && rounded(0.49999999999999994) == 0 &&
              rounded(-0.49999999999999994) == 0 && rounded(2147483646.5) == 2147483647 &&
              rounded(-2147483647.5) == -2147483648.0);

// Every point projected as `v` places it, then quantised: from here on, integers. `vertices`: storage
// to reuse.
void projectPoints(const Strands& hair, const View& v, double strandWidth, std::vector<Vertex>& vertices) {
  const glm::dmat4 toClip = v.proj * v.view;
  const glm::dvec4 depthRow(-v.view[0][2], -v.view[1][2], -v.view[2][2], -v.view[3][2]);
  const double halfX = 0.5 * v.width, halfY = 0.5 * v.height;
  const double farOff = double(kFarOff * std::max(v.width, v.height));
  resizeLarge(vertices, hair.points.size());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, hair.points.size(), 1 << 14),
                    [&](const tbb::blocked_range<size_t>& r) {
                      for (size_t i = r.begin(); i < r.end(); ++i) {
                        Vertex& q = vertices[i];
                        q = {0, 0, -1, 0};
                        const glm::dvec4 p(glm::dvec3(hair.points[i]), 1.0);
                        const glm::dvec4 clip = toClip * p;
                        if (!(clip.w > 0.0) || clip.z < -clip.w) continue;  // nearer than the near plane
                        const double x = (clip.x / clip.w + 1.0) * halfX, y = (clip.y / clip.w + 1.0) * halfY;
                        const double depth = glm::dot(depthRow, p);
                        if (!(std::abs(x - halfX) < farOff && std::abs(y - halfY) < farOff)) continue;
                        if (!(depth > 0.0 && depth / kDepthUnit < 2.0e9)) continue;
                        const double width = strandWidth * v.focalPx / depth;
                        q = {rounded(x * kSubTexel), rounded(y * kSubTexel), rounded(depth / kDepthUnit),
                             rounded(std::min(width, kWidest) * kWidthUnit)};
                      }
                    });
}

// The segments drawn: each pair of consecutive points of a strand, both drawn, by their first point.
// Found chunk by chunk of kBinChunk points, on every thread: eachSegment(c, segment) calls
// segment(first point) for chunk c's, in order.
class PointChunks {
 public:
  PointChunks(const Strands& hair, const std::vector<Vertex>& vertices)
      : firstPoint_(hair.firstPoint),
        vertices_(vertices),
        points_(firstPoint_.size() < 2 ? 0 : size_t(firstPoint_.back())) {}
  size_t count() const { return (points_ + kBinChunk - 1) / kBinChunk; }
  template <class F>
  void eachSegment(size_t c, F&& segment) const {
    const size_t lo = c * kBinChunk, hi = std::min(points_, lo + kBinChunk);
    // The end of the strand holding point lo, then of each strand the points pass into.
    size_t end =
        size_t(std::upper_bound(firstPoint_.begin(), firstPoint_.end(), uint32_t(lo)) - firstPoint_.begin());
    for (size_t i = lo; i < hi; ++i) {
      while (firstPoint_[end] <= i) ++end;
      if (i + 1 < firstPoint_[end] && vertices_[i].depth >= 0 && vertices_[i + 1].depth >= 0)
        segment(uint32_t(i));
    }
  }

 private:
  const std::vector<uint32_t>& firstPoint_;
  const std::vector<Vertex>& vertices_;
  size_t points_;
};

// A projection's list of segments, chunk by chunk of kBinChunk, as PointChunks gives them.
class SegmentChunks {
 public:
  explicit SegmentChunks(std::vector<uint32_t>&& segments) : segments_(std::move(segments)) {}
  size_t count() const { return (segments_.size() + kBinChunk - 1) / kBinChunk; }
  template <class F>
  void eachSegment(size_t c, F&& segment) const {
    for (size_t s = c * kBinChunk; s < std::min(segments_.size(), (c + 1) * kBinChunk); ++s)
      segment(segments_[s]);
  }

 private:
  const std::vector<uint32_t> segments_;
};

// Every segment `chunks` lists (count(), eachSegment(c, segment), in order) sorted by counting into
// `groups` groups, each group's in that order: groupsOf(first point, lo, hi) gives the groups [lo, hi] a
// segment goes in (none when lo > hi). Counted chunk by chunk on every thread, then each chunk's written
// in its place, so the order does not depend on the thread count. `sorted` gets them, its storage
// reused (with an eighth to spare when it grows, where `spare`); returns where each group begins in it,
// and the total last.
template <class Chunks, class GroupsOf>
std::vector<size_t> sortByCounting(const Chunks& chunks, int groups, const GroupsOf& groupsOf,
                                   std::vector<uint32_t>& sorted, bool spare) {
  const size_t count = chunks.count();
  std::vector<uint32_t> counts(count * size_t(groups), 0);
  tbb::parallel_for(size_t(0), count, [&](size_t c) {
    chunks.eachSegment(c, [&](uint32_t first) {
      int lo, hi;
      groupsOf(first, lo, hi);
      for (int g = lo; g <= hi; ++g) ++counts[c * groups + g];
    });
  });
  std::vector<size_t> groupFirst(size_t(groups) + 1, 0);
  size_t total = 0;
  for (int g = 0; g < groups; ++g) {
    groupFirst[size_t(g)] = total;
    for (size_t c = 0; c < count; ++c) {
      const uint32_t n = counts[c * groups + g];
      counts[c * groups + g] = uint32_t(total);
      total += n;
    }
  }
  groupFirst[size_t(groups)] = total;
  sorted.clear();  // what it held is not copied when the storage grows
  resizeLarge(sorted, total, spare ? total / 8 : 0);
  tbb::parallel_for(size_t(0), count, [&](size_t c) {
    chunks.eachSegment(c, [&](uint32_t first) {
      int lo, hi;
      groupsOf(first, lo, hi);
      for (int g = lo; g <= hi; ++g) sorted[counts[c * groups + g]++] = first;
    });
  });
  return groupFirst;
}

// Segments sorted into bands: `chunks` lists them (sortByCounting). `out`: its width, height and
// vertices set; its bands are made, reusing its bandSegments' storage.
template <class Chunks>
void sortIntoBands(const Chunks& chunks, Bands& out) {
  const std::vector<Vertex>& vertices = out.vertices;
  // Each segment's bands: the rows its fragments can fall in.
  const int height = out.height;
  const int bands = out.count = (height + kBandRows - 1) / kBandRows;
  auto bandsOf = [&](uint32_t first, int& lo, int& hi) {
    const Vertex &a = vertices[first], &b = vertices[first + 1];
    // A piece's cross-section reaches w·L/(2|du|) ≤ w/√2 across (¾·w here), a tent half a texel more.
    const int64_t reach = segmentReach(a, b);
    const int64_t low = floorDiv(std::min(a.y, b.y) - reach, kSubTexel);
    const int64_t high = floorDiv(std::max(a.y, b.y) + reach, kSubTexel);
    lo = 1, hi = 0;
    if (high < 0 || low >= height) return;
    lo = int(std::max<int64_t>(low, 0)) / kBandRows;
    hi = int(std::min<int64_t>(high, height - 1)) / kBandRows;
  };
  // With an eighth to spare, so the next view's bands fit when it is handed on: the 1080p coupe's
  // camera has 3% more than its light, and fresh storage for them cost a third of its projection (the
  // kernel clears every page).
  out.bandFirst = sortByCounting(chunks, bands, bandsOf, out.bandSegments, true);
}

}  // namespace

Projection project(const Strands& hair, const View& v, double strandWidth, Bands reuse) {
  Projection out;
  out.vertices = std::move(reuse.vertices);
  out.segments = std::move(reuse.bandSegments);
  out.width = v.width;
  out.height = v.height;
  projectPoints(hair, v, strandWidth, out.vertices);
  sortByCounting(
      PointChunks(hair, out.vertices), 1, [](uint32_t, int& lo, int& hi) { lo = hi = 0; }, out.segments,
      false);
  return out;
}

Bands projectIntoBands(const Strands& hair, const View& v, double strandWidth, Bands reuse) {
  // Sorted into bands straight from the points: no list of the segments is made in between (written
  // and read again, 49 MB of fresh pages for the 1080p coupe's light).
  Bands out = std::move(reuse);
  out.width = v.width;
  out.height = v.height;
  projectPoints(hair, v, strandWidth, out.vertices);
  sortIntoBands(PointChunks(hair, out.vertices), out);
  return out;
}

Bands intoBands(Projection&& p) {
  Bands out;
  out.width = p.width;
  out.height = p.height;
  out.vertices = std::move(p.vertices);
  sortIntoBands(SegmentChunks(std::move(p.segments)), out);
  return out;
}

}  // namespace hairgen::raster
