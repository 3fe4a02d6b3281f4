#include "libcore/render/light_maps.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace hairgen {

namespace {

constexpr int kBandRows = 32;                  // texel rows a thread draws at once
constexpr size_t kBinChunk = size_t(1) << 14;  // segments a thread sorts into bands at once
constexpr int32_t kNoHair = std::numeric_limits<int32_t>::max();
// A point this many map widths off the map is dropped with its segments: what it could reach of the
// map is a ribbon the view's field already holds whole (it is made to hold the scene's sphere).
constexpr int64_t kFarOff = 4;
// The widest strand drawn, texels: wider is drawn this wide. With points within kFarOff map widths of a
// map of at most 2^15 texels (OpenGL's largest), a segment is shorter than 2^27 in 1/kSubTexel, so
// width × length × a piece's length stays below 2^28 · 2^27 · 2^8 = 2^63: every product fits 64 bits.
constexpr double kWidest = 4096.0;

// Rounds toward −∞, so positions left of and right of 0 are split into texels alike.
int64_t floorDiv(int64_t a, int64_t b) {
  const int64_t q = a / b;
  return (a % b != 0 && ((a < 0) != (b < 0))) ? q - 1 : q;
}

// A point as the rasteriser reads it: x, y in 1/kSubTexel texel (window, y up), depth in kDepthUnit,
// the strand's projected width in 1/kWidthUnit texel; depth −1 when the point is not drawn.
struct Vertex {
  int32_t x, y, depth, width;
};

// base + ⌊d·t / (2n)⌋ for t = t0, t0 + 2·kSubTexel, t0 + 4·kSubTexel, …: exact, with one division to
// start and none after.
class MidpointStep {
 public:
  MidpointStep(int64_t base, int64_t d, int64_t n, int64_t t0) : den_(2 * n) {
    q_ = floorDiv(d * t0, den_);
    r_ = d * t0 - q_ * den_;
    q_ += base;
    stepQ_ = floorDiv(2 * kSubTexel * d, den_);
    stepR_ = 2 * kSubTexel * d - stepQ_ * den_;
  }
  int64_t value() const { return q_; }
  void next() {
    q_ += stepQ_;
    r_ += stepR_;
    if (r_ >= den_) {
      r_ -= den_;
      ++q_;
    }
  }

 private:
  int64_t den_, q_, r_, stepQ_, stepR_;
};

// Calls fragment(column, row, depth, coverage) for each texel the segment a → b covers, coverage in
// kCoverageOne per texel; `rowLo`, `rowHi`: the rows wanted (others may come too). Along the segment's
// major axis (x or y, whichever it moves more along) it is cut at the texel boundaries: a piece of
// length o along that axis covers the strand's width × its true length, w·o·L/|du|, exactly, so a
// strip's shared point counts once and a strand moving along itself moves its coverage continuously.
// Across, each piece is cut into ⌈extent⌉ strips of the ribbon (its extent across the major axis,
// w·L/|du| texels) and each strip is shared linearly between the two texels whose centres it lies
// between, so the maps move continuously as the strand moves across them too. Which fragments a
// segment has does not depend on the rows asked for.
template <class F>
void rasteriseSegment(Vertex a, Vertex b, int64_t rowLo, int64_t rowHi, F&& fragment) {
  const bool alongX = std::abs(int64_t(b.x) - a.x) >= std::abs(int64_t(b.y) - a.y);
  auto major = [&](const Vertex& v) { return int64_t(alongX ? v.x : v.y); };
  auto minor = [&](const Vertex& v) { return int64_t(alongX ? v.y : v.x); };
  if (major(a) > major(b)) std::swap(a, b);
  const int64_t u0 = major(a), u1 = major(b), v0 = minor(a);
  const int64_t du = u1 - u0, dv = minor(b) - v0, dz = int64_t(b.depth) - a.depth;
  if (du == 0) return;  // seen end on: no length, no area
  // The square root of an integer below 2^53 is correctly rounded in double: the same on every machine.
  const uint64_t length = uint64_t(std::sqrt(double(du * du + dv * dv)));
  const uint64_t width = (uint64_t(a.width) + uint64_t(b.width)) / 2;  // 1/kWidthUnit texel
  // The ribbon's extent across the major axis, 1/kWidthUnit texel, and the strips it is cut into.
  const uint64_t extent = width * length / uint64_t(du);
  const int64_t strips = std::max<int64_t>(1, int64_t((extent + kWidthUnit - 1) / kWidthUnit));
  // The texels along the major axis, [first, last], narrowed to those that can reach the rows.
  int64_t first = u0 >> 8, last = (u1 - 1) >> 8;
  const int64_t reach = int64_t(extent / (2 * (kWidthUnit / kSubTexel))) + 2 * kSubTexel;
  if (!alongX) {
    first = std::max(first, rowLo);
    last = std::min(last, rowHi - 1);
  } else if (dv != 0) {
    // v at a piece's middle is v0 + dv·(u − u0)/du; found in double with two texels to spare either
    // side (a texel whose fragments fall outside the rows is dropped by the caller).
    double c0 =
        (double(u0) + (double(rowLo * kSubTexel - reach) - double(v0)) * double(du) / double(dv)) / kSubTexel;
    double c1 =
        (double(u0) + (double(rowHi * kSubTexel + reach) - double(v0)) * double(du) / double(dv)) / kSubTexel;
    if (c0 > c1) std::swap(c0, c1);
    if (c0 > double(last) + 2.0 || c1 < double(first) - 2.0) return;
    first = std::max(first, int64_t(std::floor(c0)) - 2);
    last = std::min(last, int64_t(std::ceil(c1)) + 2);
  } else if (v0 + reach < rowLo * kSubTexel || v0 - reach >= rowHi * kSubTexel) {
    return;
  }
  const uint64_t perStrip =
      uint64_t(du) * (uint64_t(kWidthUnit) * kSubTexel / kCoverageOne) * uint64_t(strips);
  static_assert(kSubTexel == 256);
  // A whole texel's piece: its area, and its middle's v and depth stepped from texel to texel (the
  // middle moves 2·kSubTexel in `twice` a texel); a piece cut by the segment's end is computed on its own.
  const uint64_t wholeArea = width * kSubTexel * length / perStrip;
  const int64_t twiceFirst = 2 * first * kSubTexel + kSubTexel - 2 * u0;
  MidpointStep vStep(v0, dv, du, twiceFirst), depthStep(a.depth, dz, du, twiceFirst);
  for (int64_t c = first; c <= last; ++c, vStep.next(), depthStep.next()) {
    const int64_t lo = std::max(u0, c * kSubTexel), hi = std::min(u1, (c + 1) * kSubTexel);
    if (hi <= lo) continue;
    const bool whole = hi - lo == kSubTexel;
    // The piece's middle, as a fraction of the segment: (lo + hi − 2·u0) / (2·du).
    const int64_t twice = lo + hi - 2 * u0;
    const int64_t v = whole ? vStep.value() : v0 + floorDiv(dv * twice, 2 * du);
    const int32_t depth = int32_t(whole ? depthStep.value() : a.depth + floorDiv(dz * twice, 2 * du));
    // w·o·L/|du| per strip: 1/(kWidthUnit·kSubTexel) texel², to kCoverageOne per texel².
    const uint64_t area = whole ? wholeArea : width * uint64_t(hi - lo) * length / perStrip;
    for (int64_t k = 0; k < strips; ++k) {
      const int64_t at = strips == 1 ? v
                                     : v + floorDiv(int64_t(extent) * (2 * k + 1 - strips),
                                                    2 * strips * (kWidthUnit / kSubTexel));
      // Between the texel centres (whole + ½) either side: weights in 1/kSubTexel that sum to one.
      // (>> of a negative number rounds toward −∞ in C++20.)
      const int64_t t = at - kSubTexel / 2, m = t >> 8, f = t & 255;
      const uint32_t before = uint32_t((area * uint64_t(kSubTexel - f)) >> 8);
      const uint32_t after = uint32_t((area * uint64_t(f)) >> 8);
      if (alongX) {
        fragment(c, m, depth, before);
        fragment(c, m + 1, depth, after);
      } else {
        fragment(m, c, depth, before);
        fragment(m + 1, c, depth, after);
      }
    }
  }
}

}  // namespace

std::vector<float> HairLightMaps::startMetres(float background) const {
  std::vector<float> out(start.size());
  for (size_t i = 0; i < start.size(); ++i)
    out[i] = start[i] == kNoHair ? background : float(double(start[i]) * kDepthUnit);
  return out;
}

std::vector<glm::vec4> HairLightMaps::opacity(double strandOpacity) const {
  std::vector<glm::vec4> out(layers.size());
  const double scale = strandOpacity / double(kCoverageOne);
  for (size_t i = 0; i < layers.size(); ++i) out[i] = glm::vec4(glm::dvec4(layers[i]) * scale);
  return out;
}

HairLightMaps rasteriseLightMaps(const Strands& hair, const View& light, double strandWidth,
                                 const glm::dvec4& layerSizes) {
  const int size = light.width;
  // Every point projected as the light's view places it, then quantised: from here on, integers.
  const glm::dmat4 toClip = light.proj * light.view;
  const glm::dvec4 depthRow(-light.view[0][2], -light.view[1][2], -light.view[2][2], -light.view[3][2]);
  const double half = 0.5 * size;
  const double farOff = double(kFarOff * size);
  std::vector<Vertex> vertices(hair.points.size());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, hair.points.size(), 1 << 14),
                    [&](const tbb::blocked_range<size_t>& r) {
                      for (size_t i = r.begin(); i < r.end(); ++i) {
                        Vertex& v = vertices[i];
                        v = {0, 0, -1, 0};
                        const glm::dvec4 p(glm::dvec3(hair.points[i]), 1.0);
                        const glm::dvec4 clip = toClip * p;
                        if (!(clip.w > 0.0) || clip.z < -clip.w) continue;  // nearer than the near plane
                        const double x = (clip.x / clip.w + 1.0) * half, y = (clip.y / clip.w + 1.0) * half;
                        const double depth = glm::dot(depthRow, p);
                        if (!(std::abs(x - half) < farOff && std::abs(y - half) < farOff)) continue;
                        if (!(depth > 0.0 && depth / kDepthUnit < 2.0e9)) continue;
                        const double width = strandWidth * light.focalPx / depth;
                        v = {int32_t(std::lround(x * kSubTexel)), int32_t(std::lround(y * kSubTexel)),
                             int32_t(std::lround(depth / kDepthUnit)),
                             int32_t(std::lround(std::min(width, kWidest) * kWidthUnit))};
                      }
                    });
  // The segments: each pair of consecutive points of a strand, both drawn; by their first point.
  std::vector<uint32_t> segments;
  segments.reserve(hair.points.size());
  for (size_t s = 0; s + 1 < hair.firstPoint.size(); ++s)
    for (uint32_t i = hair.firstPoint[s]; i + 1 < hair.firstPoint[s + 1]; ++i)
      if (vertices[i].depth >= 0 && vertices[i + 1].depth >= 0) segments.push_back(i);
  // Each segment's bands: the rows its samples' texels can fall in.
  const int bands = (size + kBandRows - 1) / kBandRows;
  auto bandsOf = [&](size_t s, int& lo, int& hi) {
    const Vertex &a = vertices[segments[s]], &b = vertices[segments[s] + 1];
    const int64_t reach = std::max(a.width, b.width) / (2 * (kWidthUnit / kSubTexel)) + 2 * kSubTexel;
    const int64_t low = floorDiv(std::min(a.y, b.y) - reach, kSubTexel);
    const int64_t high = floorDiv(std::max(a.y, b.y) + reach, kSubTexel);
    lo = 1, hi = 0;
    if (high < 0 || low >= size) return;
    lo = int(std::max<int64_t>(low, 0)) / kBandRows;
    hi = int(std::min<int64_t>(high, size - 1)) / kBandRows;
  };
  // Sorted into the bands by counting, chunk by chunk.
  const size_t chunks = (segments.size() + kBinChunk - 1) / kBinChunk;
  std::vector<uint32_t> counts(chunks * size_t(bands), 0);
  tbb::parallel_for(size_t(0), chunks, [&](size_t c) {
    for (size_t s = c * kBinChunk; s < std::min(segments.size(), (c + 1) * kBinChunk); ++s) {
      int lo, hi;
      bandsOf(s, lo, hi);
      for (int b = lo; b <= hi; ++b) ++counts[c * bands + b];
    }
  });
  std::vector<size_t> bandFirst(size_t(bands) + 1, 0);
  size_t total = 0;
  for (int b = 0; b < bands; ++b) {
    bandFirst[b] = total;
    for (size_t c = 0; c < chunks; ++c) {
      const uint32_t n = counts[c * bands + b];
      counts[c * bands + b] = uint32_t(total);
      total += n;
    }
  }
  bandFirst[bands] = total;
  std::vector<uint32_t> bandSegments(total);
  tbb::parallel_for(size_t(0), chunks, [&](size_t c) {
    for (size_t s = c * kBinChunk; s < std::min(segments.size(), (c + 1) * kBinChunk); ++s) {
      int lo, hi;
      bandsOf(s, lo, hi);
      for (int b = lo; b <= hi; ++b) bandSegments[counts[c * bands + b]++] = uint32_t(s);
    }
  });
  counts = {};

  HairLightMaps maps;
  maps.size = size;
  maps.start.assign(size_t(size) * size, kNoHair);
  maps.layers.assign(size_t(size) * size, glm::uvec4(0));
  int64_t ends[4];
  double cumulative = 0.0;
  for (int k = 0; k < 4; ++k) {
    cumulative += layerSizes[k];
    ends[k] = std::llround(cumulative / kDepthUnit);
  }
  // Each band by one thread: first where the hair begins in its rows, then the layers' sums.
  tbb::parallel_for(0, bands, [&](int band) {
    const int64_t rowLo = int64_t(band) * kBandRows, rowHi = std::min<int64_t>(size, rowLo + kBandRows);
    auto eachFragment = [&](auto&& texel) {
      for (size_t k = bandFirst[band]; k < bandFirst[band + 1]; ++k) {
        const uint32_t first = segments[bandSegments[k]];
        rasteriseSegment(vertices[first], vertices[first + 1], rowLo, rowHi,
                         [&](int64_t i, int64_t j, int32_t depth, uint32_t coverage) {
                           if (coverage == 0 || j < rowLo || j >= rowHi || i < 0 || i >= size) return;
                           texel(size_t(j) * size + size_t(i), depth, coverage);
                         });
      }
    };
    eachFragment([&](size_t t, int32_t depth, uint32_t) { maps.start[t] = std::min(maps.start[t], depth); });
    eachFragment([&](size_t t, int32_t depth, uint32_t coverage) {
      const int64_t behind = int64_t(depth) - maps.start[t];
      glm::uvec4& sum = maps.layers[t];
      for (int k = 0; k < 3; ++k)
        if (behind < ends[k]) sum[k] += coverage;
      sum[3] += coverage;
    });
  });
  return maps;
}

}  // namespace hairgen
