#include "libcore/render/light_maps.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

namespace hairgen {

namespace {

constexpr int32_t kNoHair = std::numeric_limits<int32_t>::max();

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
                                 const glm::dvec4& layerSizes, raster::Bands* spent) {
  const int size = light.width;
  raster::Bands bands = raster::projectIntoBands(hair, light, strandWidth);
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
  // Each band by one thread, its fragments kept while it is drawn (a band's, not the map's: a few MB):
  // first where the hair begins in its rows, then the layers' sums.
  struct Fragment {
    uint32_t texel;
    int32_t depth;
    uint32_t coverage;
  };
  tbb::enumerable_thread_specific<std::vector<Fragment>> kept;
  tbb::parallel_for(0, bands.count, [&](int band) {
    std::vector<Fragment>& fragments = kept.local();
    fragments.clear();
    bands.eachFragment<raster::Across::kTent>(
        band, [&](size_t t, int32_t depth, uint32_t coverage, uint32_t, raster::Piece) {
          maps.start[t] = std::min(maps.start[t], depth);
          fragments.push_back({uint32_t(t), depth, coverage});
        });
    for (const Fragment& f : fragments) {
      const int64_t behind = int64_t(f.depth) - maps.start[f.texel];
      glm::uvec4& sum = maps.layers[f.texel];
      for (int k = 0; k < 3; ++k)
        if (behind < ends[k]) raster::addSaturating(sum[k], f.coverage);
      raster::addSaturating(sum[3], f.coverage);
    }
  });
  if (spent) *spent = std::move(bands);
  return maps;
}

}  // namespace hairgen
