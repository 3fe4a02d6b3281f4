// The light's two hair maps (where the hair begins, and the deep opacity layers behind it: Yuksel &
// Keyser 2008, as the thesis uses them in §4.1.6), drawn by hairgen's own rasteriser on every machine,
// so a GPU and llvmpipe shadow the hair with the same bits.
//
// Every point is projected once in double precision and quantised: window x and y to 1/kSubTexel of a
// texel, depth along the light's axis to kDepthUnit, the strand's projected width to 1/kWidthUnit of a
// texel. From there on everything is integer arithmetic. Each segment is a thin ribbon of the strand's
// width (Kajiya & Kay's cylinder seen from the light), cut at the texel boundaries along its major axis
// (x or y, whichever it moves more along): each piece covers the strand's width × its true length
// within that texel column (or row), exactly, and is shared linearly between the two texels across it
// whose centres it lies between (a ribbon wider than a texel is first cut into strips a texel wide),
// so the maps change continuously as a strand moves, and a strip's shared point counts once.
//
// The depth map keeps, per texel, the nearest sample that reaches it; the opacity map adds each
// sample's coverage (texel² in 1/kCoverageOne) to its layer and every layer behind it, measured from
// where the hair begins. Integer sums and minima do not depend on the order they are taken in, so the
// maps are the same bits on any thread count. Pure math: no OpenGL.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "libcore/model/strands.h"
#include "libcore/render/views.h"

namespace hairgen {

// Window positions are kept in 1/kSubTexel texel: 8 bits of sub-texel position, as GPUs snap vertices.
inline constexpr int kSubTexel = 256;
// A strand's projected width in 1/kWidthUnit texel, so a strand a tenth of a texel wide covers what it
// should to 0.2% (products with a length in 1/kSubTexel still fit in 64 bits).
inline constexpr int kWidthUnit = 1 << 16;
// Depth along the light's axis in whole micrometres: a 40 µm strand is 40 units, and 2^31 units reach
// 2 km.
inline constexpr double kDepthUnit = 1.0e-6;
// A texel fully covered once, in coverage units.
inline constexpr uint32_t kCoverageOne = 1u << 16;

// The light's maps as integers, and as the floats the shadow lookup reads.
struct HairLightMaps {
  int size = 0;                    // texels per side
  std::vector<int32_t> start;      // kDepthUnit, where the hair begins; INT32_MAX where none reached
  std::vector<glm::uvec4> layers;  // coverage (kCoverageOne = a texel) within each layer's far end
  // Metres along the light's axis (`background` where no hair is), rows from the bottom.
  std::vector<float> startMetres(float background) const;
  // Each layer's opacity: coverage × `strandOpacity` (a texel covered once by a strand is that opaque).
  std::vector<glm::vec4> opacity(double strandOpacity) const;
};

// `light`: a square perspective view (its width texels per side). `strandWidth`: the strands' diameter,
// metres. `layerSizes`: the four layers' depths, metres. A segment with a point nearer than the near
// plane is dropped.
HairLightMaps rasteriseLightMaps(const Strands& hair, const View& light, double strandWidth,
                                 const glm::dvec4& layerSizes);

}  // namespace hairgen
