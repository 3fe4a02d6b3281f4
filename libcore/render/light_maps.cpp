#include "libcore/render/light_maps.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace hairgen {

namespace {

constexpr int kBandRows = 16;                  // texel rows a thread draws at once
constexpr size_t kBinChunk = size_t(1) << 14;  // segments a thread sorts into bands at once
constexpr int32_t kNoHair = std::numeric_limits<int32_t>::max();
// A point this many map widths off the map is dropped with its segments: what it could reach of the
// map is a ribbon the view's field already holds whole (it is made to hold the scene's sphere).
constexpr int64_t kFarOff = 4;

// Rounds toward −∞, so positions left of and right of 0 are split into texels alike.
int64_t floorDiv(int64_t a, int64_t b) {
  const int64_t q = a / b;
  return (a % b != 0 && ((a < 0) != (b < 0))) ? q - 1 : q;
}

int64_t ceilDiv(int64_t a, int64_t b) {
  return -floorDiv(-a, b);
}

// A point as the rasteriser reads it: x, y in 1/kSubTexel texel (window, y up), depth in kDepthUnit,
// the strand's projected width in 1/kWidthUnit texel; depth −1 when the point is not drawn.
struct Vertex {
  int32_t x, y, depth, width;
};

struct Sample {
  int64_t x, y;   // 1/kSubTexel texel
  int64_t depth;  // kDepthUnit
  uint64_t area;  // coverage units
};

// Calls `sample` for each midpoint of the segment a → b: `perTexel` positions per texel along it and
// across its width, each carrying the ribbon's area divided among them (rounded down).
template <class F>
void sampleSegment(const Vertex& a, const Vertex& b, int perTexel, F&& sample) {
  const int64_t dx = int64_t(b.x) - a.x, dy = int64_t(b.y) - a.y;
  const int64_t lengthSquared = dx * dx + dy * dy;
  if (lengthSquared == 0) return;  // seen end on: no length, no area
  // The square root of an integer below 2^53 is correctly rounded in double: the same on every machine.
  const int64_t length = int64_t(std::sqrt(double(lengthSquared)));
  if (length == 0) return;
  const int64_t along = std::max<int64_t>(1, ceilDiv(length * perTexel, kSubTexel));
  const int64_t across =
      std::max<int64_t>(1, ceilDiv(int64_t(std::max(a.width, b.width)) * perTexel, kWidthUnit));
  // The unit normal on the image, in 1/kSubTexel.
  const int64_t nx = -dy * kSubTexel / length, ny = dx * kSubTexel / length;
  for (int64_t i = 0; i < along; ++i) {
    const int64_t num = 2 * i + 1, den = 2 * along;
    const int64_t cx = a.x + floorDiv(dx * num, den), cy = a.y + floorDiv(dy * num, den);
    const int64_t depth = a.depth + floorDiv((int64_t(b.depth) - a.depth) * num, den);
    const int64_t width = a.width + floorDiv((int64_t(b.width) - a.width) * num, den);
    // width × length / samples, in 1/(kWidthUnit·kSubTexel) texel², to kCoverageOne per texel².
    const uint64_t area = uint64_t(width * length) /
                          uint64_t(along * across * (int64_t(kWidthUnit) * kSubTexel / kCoverageOne));
    for (int64_t j = 0; j < across; ++j) {
      const int64_t offset = floorDiv(width * (2 * j + 1 - across), 2 * across * (kWidthUnit / kSubTexel));
      sample(
          Sample{cx + floorDiv(offset * nx, kSubTexel), cy + floorDiv(offset * ny, kSubTexel), depth, area});
    }
  }
}

// The four texels around a sample (centres at whole + ½) and their bilinear weights, in
// 1/kSubTexel², summing to kSubTexel².
template <class F>
void splat(const Sample& s, F&& texel) {
  const int64_t u = s.x - kSubTexel / 2, v = s.y - kSubTexel / 2;
  const int64_t i = floorDiv(u, kSubTexel), j = floorDiv(v, kSubTexel);
  const int64_t fx = u - i * kSubTexel, fy = v - j * kSubTexel;
  texel(i, j, uint64_t((kSubTexel - fx) * (kSubTexel - fy)));
  texel(i + 1, j, uint64_t(fx * (kSubTexel - fy)));
  texel(i, j + 1, uint64_t((kSubTexel - fx) * fy));
  texel(i + 1, j + 1, uint64_t(fx * fy));
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

HairLightMaps rasteriseLightMaps(const Strands& hair, const View& light, double strandWidth, int samples,
                                 const glm::dvec4& layerSizes) {
  const int size = light.width;
  const int perTexel = std::max(samples, 1);
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
                             int32_t(std::lround(std::min(width, farOff) * kWidthUnit))};
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
    auto eachTexel = [&](auto&& texel) {
      for (size_t k = bandFirst[band]; k < bandFirst[band + 1]; ++k) {
        const uint32_t first = segments[bandSegments[k]];
        sampleSegment(vertices[first], vertices[first + 1], perTexel, [&](const Sample& s) {
          splat(s, [&](int64_t i, int64_t j, uint64_t weight) {
            if (weight == 0 || j < rowLo || j >= rowHi || i < 0 || i >= size) return;
            texel(size_t(j) * size + size_t(i), s, weight);
          });
        });
      }
    };
    eachTexel([&](size_t t, const Sample& s, uint64_t) {
      maps.start[t] = std::min(maps.start[t], int32_t(s.depth));
    });
    eachTexel([&](size_t t, const Sample& s, uint64_t weight) {
      const uint32_t c = uint32_t((s.area * weight) / uint64_t(kSubTexel * kSubTexel));
      const int64_t behind = s.depth - maps.start[t];
      glm::uvec4& sum = maps.layers[t];
      for (int k = 0; k < 3; ++k)
        if (behind < ends[k]) sum[k] += c;
      sum[3] += c;
    });
  });
  return maps;
}

}  // namespace hairgen
