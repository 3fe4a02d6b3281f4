// Greedy chord decimation of line strips, as line_decimation.h describes. The test, every dropped point
// within a tolerance of its chord, is Ramer's (1972) and Douglas and Peucker's (1973); the walk is greedy
// from the root rather than their recursive split, so a strip is made in one pass and its chords are
// bounded in length.
#include "libcore/render/line_decimation.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <glm/glm.hpp>

namespace hairgen {
namespace {

// Marks in `keep` (one flag per point of strand s) the points its strip keeps; returns how many. In
// floats, as the points are: a tolerance is a fraction of a pixel, ten thousand times a float's rounding
// at a head's size.
uint32_t keepPoints(const Strands& strands, size_t s, float tolerance2, uint8_t* keep) {
  const glm::vec3* point = &strands.points[strands.firstPoint[s]];
  const uint32_t n = strands.pointsOf(s);
  uint32_t kept = 1, a = 0;
  keep[0] = 1;
  while (a + 1 < n) {
    uint32_t b = a + 1;  // the farthest point whose chord from a holds every point between
    for (uint32_t c = a + 2; c < n && c - a <= kMostSegmentsPerChord; ++c) {
      const glm::vec3 chord = point[c] - point[a];
      const float length2 = glm::dot(chord, chord);
      const float inverse = length2 > 0.0f ? 1.0f / length2 : 0.0f;
      bool holds = true;
      for (uint32_t k = a + 1; k < c && holds; ++k) {  // the distance from point k to the chord
        const glm::vec3 along = point[k] - point[a];
        const float t = glm::clamp(glm::dot(along, chord) * inverse, 0.0f, 1.0f);
        const glm::vec3 off = along - t * chord;
        holds = glm::dot(off, off) <= tolerance2;
      }
      if (!holds) break;
      b = c;
    }
    keep[b] = 1;
    ++kept;
    a = b;
  }
  return kept;
}

}  // namespace

std::vector<uint32_t> decimatedLineStrips(const Strands& strands, double tolerance,
                                          const std::vector<uint32_t>& order) {
  std::vector<uint32_t> all;
  if (order.empty())
    for (uint32_t s = 0; s < strands.strandCount(); ++s)
      if (strands.pointsOf(s) >= 2) all.push_back(s);
  const std::vector<uint32_t>& drawn = order.empty() ? all : order;
  // The points each strip keeps, strand by strand in memory order (then gathered in `order`).
  std::vector<uint8_t> keep(strands.pointCount(), 0);
  std::vector<uint32_t> kept(strands.strandCount(), 0);
  const float tolerance2 = float(tolerance * tolerance);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, strands.strandCount(), 1024),
                    [&](const tbb::blocked_range<size_t>& r) {
                      for (size_t s = r.begin(); s != r.end(); ++s)
                        if (strands.pointsOf(s) >= 2)
                          kept[s] = keepPoints(strands, s, tolerance2, &keep[strands.firstPoint[s]]);
                    });
  std::vector<uint64_t> first(drawn.size() + 1, 0);  // per strip, where it starts in the indices
  for (size_t k = 0; k < drawn.size(); ++k) first[k + 1] = kept[drawn[k]] + 1;  // + the restart
  for (size_t k = 0; k < drawn.size(); ++k) first[k + 1] += first[k];
  std::vector<uint32_t> indices(first.back());
  tbb::parallel_for(size_t(0), drawn.size(), [&](size_t k) {
    const uint32_t s = drawn[k];
    uint64_t at = first[k];
    for (uint32_t p = strands.firstPoint[s]; p < strands.firstPoint[s] + strands.pointsOf(s); ++p)
      if (keep[p]) indices[at++] = p;
    indices[at] = kRestartIndex;
  });
  return indices;
}

}  // namespace hairgen
