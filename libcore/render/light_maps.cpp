#include "libcore/render/light_maps.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "libcore/render/line_decimation.h"

namespace hairgen {

namespace {

constexpr int kBandRows = 16;                  // texel rows a thread draws at once
constexpr size_t kBinChunk = size_t(1) << 14;  // segments a thread sorts into bands at once

}  // namespace

LightRaster::LightRaster(const Strands& hair, const std::vector<uint32_t>& strips, const View& light)
    : size_(light.width) {
  // Every strip point projected, as the vertex stage and the viewport transform place it.
  const glm::dmat4 toClip = light.proj * light.view;
  const glm::dvec4 depthRow(-light.view[0][2], -light.view[1][2], -light.view[2][2], -light.view[3][2]);
  const double half = 0.5 * size_;
  vertices_.resize(strips.size());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, strips.size(), 1 << 14),
                    [&](const tbb::blocked_range<size_t>& r) {
                      for (size_t i = r.begin(); i < r.end(); ++i) {
                        Vertex& v = vertices_[i];
                        v = {0.0f, 0.0f, std::numeric_limits<float>::quiet_NaN(), 0.0f};
                        if (strips[i] == kRestartIndex) continue;
                        const glm::dvec4 p(glm::dvec3(hair.points[strips[i]]), 1.0);
                        const glm::dvec4 clip = toClip * p;
                        // Nearer than the near plane (or at or behind the light): OpenGL would clip
                        // the segment and draw the rest; this drops it. Never so inside the scene's sphere
                        // with the light outside it, which the CPU's maps need (passes.cpp).
                        if (!(clip.w > 0.0) || clip.z < -clip.w) continue;
                        const double invW = 1.0 / clip.w;
                        const double x = (clip.x * invW + 1.0) * half, y = (clip.y * invW + 1.0) * half;
                        if (!(std::abs(x) < 1e9 && std::abs(y) < 1e9))
                          continue;  // far off: floats stay finite
                        v = {float(x), float(y), float(invW), float(glm::dot(depthRow, p) * invW)};
                      }
                    });
  // The segments: each pair of consecutive points of a strip, both projected.
  auto drawable = [&](size_t i) {
    return !std::isnan(vertices_[i].invW) && !std::isnan(vertices_[i + 1].invW);
  };
  for (size_t i = 0; i + 1 < strips.size(); ++i)
    if (drawable(i)) segments_.push_back(static_cast<uint32_t>(i));
  // Each segment's bands: the rows its texels can fall in, a row to spare either side.
  const int bands = (size_ + kBandRows - 1) / kBandRows;
  auto bandsOf = [&](uint32_t s, int& lo, int& hi) {
    const Vertex &a = vertices_[segments_[s]], &b = vertices_[segments_[s] + 1];
    const float low = std::min(a.y, b.y) - 1.0f, high = std::max(a.y, b.y) + 1.0f;
    lo = 1, hi = 0;
    if (!(high >= 0.0f) || !(low < float(size_))) return;
    lo = int(std::max(low, 0.0f)) / kBandRows;
    hi = int(std::min(high, float(size_ - 1))) / kBandRows;
  };
  // Sorted into the bands by counting, chunk by chunk in order, so each band lists its segments in
  // drawing order.
  const size_t chunks = (segments_.size() + kBinChunk - 1) / kBinChunk;
  std::vector<uint32_t> counts(chunks * size_t(bands), 0);
  tbb::parallel_for(size_t(0), chunks, [&](size_t c) {
    for (size_t s = c * kBinChunk; s < std::min(segments_.size(), (c + 1) * kBinChunk); ++s) {
      int lo, hi;
      bandsOf(uint32_t(s), lo, hi);
      for (int b = lo; b <= hi; ++b) ++counts[c * bands + b];
    }
  });
  bandFirst_.assign(size_t(bands) + 1, 0);
  uint32_t total = 0;
  for (int b = 0; b < bands; ++b) {
    bandFirst_[b] = total;
    for (size_t c = 0; c < chunks; ++c) {
      const uint32_t n = counts[c * bands + b];
      counts[c * bands + b] = total;  // now where the chunk's segments of band b go
      total += n;
    }
  }
  bandFirst_[bands] = total;
  bandSegments_.resize(total);
  tbb::parallel_for(size_t(0), chunks, [&](size_t c) {
    for (size_t s = c * kBinChunk; s < std::min(segments_.size(), (c + 1) * kBinChunk); ++s) {
      int lo, hi;
      bandsOf(uint32_t(s), lo, hi);
      for (int b = lo; b <= hi; ++b) bandSegments_[counts[c * bands + b]++] = uint32_t(s);
    }
  });
}

// Calls fragment(texel index, depth) for every fragment of the band's segments in its rows, segment by
// segment in drawing order. Which texels a segment covers does not depend on the band: each fragment is
// found from its own column (or row) centre, and the band only keeps those in its rows.
template <class Fragment>
void LightRaster::drawBand(int band, Fragment&& fragment) const {
  const int rowLo = band * kBandRows, rowHi = std::min(size_, rowLo + kBandRows);
  const float last = float(size_ - 1);
  for (uint32_t k = bandFirst_[band]; k < bandFirst_[band + 1]; ++k) {
    const Vertex& a = vertices_[segments_[bandSegments_[k]]];
    const Vertex& b = vertices_[segments_[bandSegments_[k]] + 1];
    const float dx = b.x - a.x, dy = b.y - a.y;
    auto depthAt = [&](float t) {  // perspective-correct: depth/w and 1/w are linear on the image
      return (a.depthOverW + t * (b.depthOverW - a.depthOverW)) / (a.invW + t * (b.invW - a.invW));
    };
    const bool alongX = std::abs(dx) >= std::abs(dy);
    const float major0 = alongX ? a.x : a.y, major1 = alongX ? b.x : b.y;
    const float dMajor = alongX ? dx : dy, dMinor = alongX ? dy : dx;
    const float minor0 = alongX ? a.y : a.x;
    if (dMajor == 0.0f) continue;  // a point: no line
    // The texel centres c + 0.5 along the major axis from the segment's start, up to but not at its end.
    float from = dMajor > 0.0f ? std::ceil(major0 - 0.5f) : std::floor(major1 - 0.5f) + 1.0f;
    float to = dMajor > 0.0f ? std::ceil(major1 - 0.5f) - 1.0f : std::floor(major0 - 0.5f);
    from = std::max(from, 0.0f);
    to = std::min(to, alongX ? last : float(rowHi - 1));
    if (!alongX) from = std::max(from, float(rowLo));
    if (!(from <= to)) continue;  // nothing in the band or the map (or a NaN): no int of a huge float
    // A fragment's row (or column) across the major axis, as the loop below computes it.
    auto minorAt = [&](int m) { return std::floor(minor0 + (float(m) + 0.5f - major0) / dMajor * dMinor); };
    if (alongX) {
      // The columns whose row lies in the band: an interval, since the row is monotone in the column
      // (every step of it rounds monotonically), found with the row's own arithmetic, so a band draws
      // exactly the columns the per-column test below keeps (an estimate from the slope misses some
      // where a row's rounding divided by a small slope is many columns).
      const bool rising = (dMinor > 0.0f) == (dMajor > 0.0f);
      // The first column in [lo, hi] where `past` holds (it holds from some column on), or hi + 1.
      auto first = [](int lo, int hi, auto past) {
        while (lo <= hi) {
          const int mid = lo + (hi - lo) / 2;
          if (past(mid))
            hi = mid - 1;
          else
            lo = mid + 1;
        }
        return lo;
      };
      const int lo = int(from), hi = int(to);
      const int begin = rising ? first(lo, hi, [&](int m) { return minorAt(m) >= float(rowLo); })
                               : first(lo, hi, [&](int m) { return minorAt(m) < float(rowHi); });
      const int end = rising ? first(lo, hi, [&](int m) { return minorAt(m) >= float(rowHi); })
                             : first(lo, hi, [&](int m) { return minorAt(m) < float(rowLo); });
      from = float(begin);
      to = float(end - 1);
      if (!(from <= to)) continue;
    }
    for (int m = int(from); m <= int(to); ++m) {
      const float minor = minorAt(m);
      if (alongX ? !(minor >= float(rowLo) && minor < float(rowHi)) : !(minor >= 0.0f && minor <= last))
        continue;
      const int column = alongX ? m : int(minor), row = alongX ? int(minor) : m;
      fragment(size_t(row) * size_t(size_) + size_t(column), depthAt((float(m) + 0.5f - major0) / dMajor));
    }
  }
}

std::vector<float> LightRaster::depth(float background) const {
  std::vector<float> start(size_t(size_) * size_t(size_), background);
  const int bands = int(bandFirst_.size()) - 1;
  tbb::parallel_for(0, bands, [&](int band) {
    drawBand(band, [&](size_t texel, float d) { start[texel] = std::min(start[texel], d); });
  });
  return start;
}

std::vector<glm::vec4> LightRaster::opacity(const std::vector<float>& start, const glm::vec4& layers,
                                            float alpha) const {
  std::vector<glm::vec4> sums(size_t(size_) * size_t(size_), glm::vec4(0.0f));
  // The layers' far ends from where the hair begins, as opacity_fragment.glsl sums them.
  const glm::vec4 ends(layers.x, layers.x + layers.y, layers.x + layers.y + layers.z,
                       layers.x + layers.y + layers.z + layers.w);
  const int bands = int(bandFirst_.size()) - 1;
  tbb::parallel_for(0, bands, [&](int band) {
    drawBand(band, [&](size_t texel, float d) {
      const glm::vec4 end = start[texel] + ends;
      sums[texel] +=
          glm::vec4(d < end.x ? alpha : 0.0f, d < end.y ? alpha : 0.0f, d < end.z ? alpha : 0.0f, alpha);
    });
  });
  return sums;
}

}  // namespace hairgen
