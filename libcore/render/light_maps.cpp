#include "libcore/render/light_maps.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

namespace hairgen {

namespace {

constexpr int32_t kNoHair = std::numeric_limits<int32_t>::max();

struct Fragment {
  uint32_t texel;
  int32_t depth;
  uint32_t coverage;
};

// The fragments a band keeps while it is drawn, in blocks of kBlock, kept from band to band. A band of
// the 1080p coupe's light keeps up to 1.9 million (23 MB; it drew up to 90 MB's before only those near
// where the hair begins were kept); in a vector that doubled to hold them, its new storage and its old
// were held at once as it grew, on each thread: the render's peak was 896 MB with it, 802 MB with
// blocks (150,021 strands, 1920x1080, /usr/bin/time's maximum resident set; docs/performance.md).
class FragmentBlocks {
 public:
  void clear() { size_ = 0; }
  void push(const Fragment& f) {
    if (size_ == blocks_.size() * kBlock)
      blocks_.push_back(std::make_unique_for_overwrite<Fragment[]>(kBlock));
    blocks_[size_ / kBlock][size_ % kBlock] = f;
    ++size_;
  }
  template <class F>
  void forEach(F&& f) const {
    for (size_t b = 0; b * kBlock < size_; ++b) {
      const Fragment* block = blocks_[b].get();
      for (size_t i = 0, n = std::min(kBlock, size_ - b * kBlock); i < n; ++i) f(block[i]);
    }
  }

 private:
  static constexpr size_t kBlock = size_t(1) << 16;  // fragments: 768 KB
  std::vector<std::unique_ptr<Fragment[]>> blocks_;
  size_t size_ = 0;
};

float metres(int32_t start, float background) {
  return start == kNoHair ? background : float(double(start) * kDepthUnit);
}

glm::vec4 opacityOf(const glm::uvec4& coverage, double scale) {
  return glm::vec4(glm::dvec4(coverage) * scale);
}

// f(i) for every texel, on every thread.
template <class F>
void eachTexel(size_t texels, F&& f) {
  tbb::parallel_for(tbb::blocked_range<size_t>(0, texels, size_t(1) << 16),
                    [&](const tbb::blocked_range<size_t>& r) {
                      for (size_t i = r.begin(); i < r.end(); ++i) f(i);
                    });
}

// Throws when a map's integers were written over for its upload.
void requireIntegers(bool spent, const char* map) {
  if (spent)
    throw std::logic_error(std::string("the light's ") + map + " map was already converted in place");
}

}  // namespace

std::vector<float> HairLightMaps::startMetres(float background) const {
  requireIntegers(startSpent_, "start");
  std::vector<float> out(start.size());
  eachTexel(start.size(), [&](size_t i) { out[i] = metres(start[i], background); });
  return out;
}

std::vector<glm::vec4> HairLightMaps::opacity(double strandOpacity) const {
  requireIntegers(layersSpent_, "opacity");
  std::vector<glm::vec4> out(layers.size());
  const double scale = strandOpacity / double(kCoverageOne);
  eachTexel(layers.size(), [&](size_t i) { out[i] = opacityOf(layers[i], scale); });
  return out;
}

const void* HairLightMaps::startMetresInPlace(float background) {
  requireIntegers(startSpent_, "start");
  startSpent_ = true;
  eachTexel(start.size(), [&](size_t i) { start[i] = std::bit_cast<int32_t>(metres(start[i], background)); });
  return start.data();
}

const void* HairLightMaps::opacityInPlace(double strandOpacity) {
  requireIntegers(layersSpent_, "opacity");
  layersSpent_ = true;
  const double scale = strandOpacity / double(kCoverageOne);
  eachTexel(layers.size(),
            [&](size_t i) { layers[i] = std::bit_cast<glm::uvec4>(opacityOf(layers[i], scale)); });
  return layers.data();
}

std::array<int64_t, 3> layerEnds(const glm::dvec4& layerSizes) {
  std::array<int64_t, 3> ends;
  double cumulative = 0.0;
  for (int k = 0; k < 3; ++k) {
    cumulative += layerSizes[k];
    ends[k] = std::llround(cumulative / kDepthUnit);
  }
  return ends;
}

HairLightMaps rasteriseLightMaps(const Strands& hair, const View& light, double strandWidth,
                                 const glm::dvec4& layerSizes, raster::Bands* spent) {
  const int size = light.width;
  raster::Bands bands = raster::projectIntoBands(hair, light, strandWidth);
  HairLightMaps maps;
  maps.size = size;
  maps.start.assign(size_t(size) * size, kNoHair);
  maps.layers.assign(size_t(size) * size, glm::uvec4(0));
  const std::array<int64_t, 3> ends = layerEnds(layerSizes);
  // The farthest behind where the hair begins that a fragment can lie and still be in one of the first
  // three layers.
  const int64_t reach = std::max({ends[0], ends[1], ends[2]});
  // Each band by one thread: where the hair begins in its rows and the fourth layer (every fragment)
  // as it is drawn, then the first three layers' sums from the fragments it kept. Only a fragment
  // within `reach` of the nearest drawn before it in its texel is kept: where the hair begins is no
  // deeper than that nearest, so one farther behind is behind every first three layers' far end (most
  // of a thick coupe's fragments: the 1080p coupe keeps 26 million of its 109 million).
  tbb::enumerable_thread_specific<FragmentBlocks> kept;
  tbb::parallel_for(0, bands.count, [&](int band) {
    FragmentBlocks& fragments = kept.local();
    fragments.clear();
    bands.eachFragment<raster::Across::kTent>(
        band, [&](size_t t, int32_t depth, uint32_t coverage, uint32_t, raster::Piece) {
          int32_t& start = maps.start[t];
          start = std::min(start, depth);
          raster::addSaturating(maps.layers[t][3], coverage);
          if (int64_t(depth) - start < reach) fragments.push({uint32_t(t), depth, coverage});
        });
    fragments.forEach([&](const Fragment& f) {
      const int64_t behind = int64_t(f.depth) - maps.start[f.texel];
      glm::uvec4& sum = maps.layers[f.texel];
      for (int k = 0; k < 3; ++k)
        if (behind < ends[k]) raster::addSaturating(sum[k], f.coverage);
    });
  });
  if (spent) *spent = std::move(bands);
  return maps;
}

}  // namespace hairgen
