// The light's two hair maps (where the hair begins, and the deep opacity layers behind it: Yuksel &
// Keyser 2008, as the thesis uses them in §4.1.6), drawn by hairgen's own integer rasteriser
// (hair_raster.h, the one the camera's view uses) on every machine, so a GPU and llvmpipe shadow the
// hair with the same bits.
//
// The depth map keeps, per texel, the nearest sample that reaches it; the opacity map adds each
// sample's coverage (texel² in 1/kCoverageOne) to its layer and every layer behind it, measured from
// where the hair begins. Integer sums and minima do not depend on the order they are taken in, so the
// maps are the same bits on any thread count. Pure math: no OpenGL.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "libcore/model/strands.h"
#include "libcore/render/hair_raster.h"
#include "libcore/render/views.h"

namespace hairgen {

// The light's maps as integers, and as the floats the shadow lookup reads.
struct HairLightMaps {
  int size = 0;                    // texels per side
  std::vector<int32_t> start;      // kDepthUnit, where the hair begins; INT32_MAX where none reached
  std::vector<glm::uvec4> layers;  // coverage (kCoverageOne = a texel) within each layer's far end
  // Metres along the light's axis (`background` where no hair is), rows from the bottom.
  std::vector<float> startMetres(float background) const;
  // Each layer's opacity: coverage × `strandOpacity` (a texel covered once by a strand is that opaque).
  std::vector<glm::vec4> opacity(double strandOpacity) const;
  // The same floats written over the integers' own storage, each float's bits in its integer's place,
  // for an upload that needs no second copy of a map (the 1080p coupe's two: 49 MB of fresh pages,
  // which the kernel clears first). For a map's last use: its integers are gone after, and a second
  // call, or startMetres() or opacity() after one, throws std::logic_error.
  const void* startMetresInPlace(float background);
  const void* opacityInPlace(double strandOpacity);

 private:
  bool startSpent_ = false, layersSpent_ = false;  // written over by the calls above
};

// The first three layers' far ends behind where the hair begins, in kDepthUnit: `layerSizes` (metres)
// summed in turn, each sum rounded. The fourth layer holds everything behind. The CPU's maps and the
// device's (compute_raster.h) both take them from here.
std::array<int64_t, 3> layerEnds(const glm::dvec4& layerSizes);

// `light`: a square perspective view (its width texels per side). `strandWidth`: the strands' diameter,
// metres. `layerSizes`: the four layers' depths, metres. A segment with a point nearer than the near
// plane is dropped. `spent`: null, or where the light's bands are left once drawn, for the next
// projection to reuse (hair_raster.h: project).
HairLightMaps rasteriseLightMaps(const Strands& hair, const View& light, double strandWidth,
                                 const glm::dvec4& layerSizes, raster::Bands* spent = nullptr);

}  // namespace hairgen
