// The light's two hair maps (where the hair begins, and the deep opacity layers behind that) drawn on
// the CPU, for a software rasteriser: llvmpipe pushes every line through one serial thread for set-up
// and binning and spends ~15 ns a fragment, and these two passes were two fifths of a 1080p render of
// 150,000 strands. Here each strand's chords are projected once, sorted into bands of texel rows, and
// each band is drawn by one thread in the strands' order: the same maps whatever the thread count.
//
// The rules are a one-texel line's, close to OpenGL's for lines of width 1 (whose diamond-exit rule
// differs at a line's ends): along a segment's major axis,
// one fragment per texel column (or row) whose centre the segment passes, half-open at its end so a
// strip's shared points are drawn once; the fragment's texel is the one the segment crosses at that
// centre. Depth is interpolated perspective-correctly (as a varying is). The depth map keeps the
// nearest fragment's depth; the opacity map adds each fragment's opacity to its layer and every layer
// behind it, as opacity_fragment.glsl does with additive blending. Pure math: no OpenGL.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "libcore/model/strands.h"
#include "libcore/render/views.h"

namespace hairgen {

class LightRaster {
 public:
  // `strips`: line strips of point indices into `hair`'s points, each ended by kRestartIndex
  // (line_decimation.h). `light`: a square view (its width texels per side).
  LightRaster(const Strands& hair, const std::vector<uint32_t>& strips, const View& light);

  int size() const { return size_; }
  // Metres along the light's axis to the nearest hair fragment of each texel, rows from the bottom;
  // `background` where no hair was drawn.
  std::vector<float> depth(float background) const;
  // Per texel, RGBA: the opacity of the fragments within layers.x of the texel's `start`, within
  // layers.x + layers.y, and so on; the last channel every fragment's. Each fragment adds `alpha`.
  std::vector<glm::vec4> opacity(const std::vector<float>& start, const glm::vec4& layers, float alpha) const;

 private:
  // A projected point: window position in texels (x right, y up), and 1/w and depth/w for the
  // perspective-correct depth.
  struct Vertex {
    float x, y, invW, depthOverW;
  };
  template <class Fragment>
  void drawBand(int band, Fragment&& fragment) const;

  int size_ = 0;
  std::vector<Vertex> vertices_;        // the strips' points, projected, in their order
  std::vector<uint32_t> segments_;      // each segment's first vertex (the next one ends it)
  std::vector<uint32_t> bandFirst_;     // per band of kBandRows rows, where its segments start, + 1
  std::vector<uint32_t> bandSegments_;  // the segments touching each band, in drawing order
};

}  // namespace hairgen
