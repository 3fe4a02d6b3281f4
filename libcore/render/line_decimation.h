// Fewer vertices for drawing strands as lines where the drawing cannot tell: a strand's polyline is
// replaced by chords through some of its points, each skipped point within `tolerance` of its chord
// (the classic polyline simplification's test, applied greedily from the root). The light's passes draw
// hair into maps whose texels are far coarser than a segment's bend, so most of their vertices, which
// llvmpipe transforms on one thread, buy nothing (README, Rendering).
#pragma once

#include <cstdint>
#include <vector>

#include "libcore/model/strands.h"

namespace hairgen {

// The index that ends one line strip and starts the next (GL_PRIMITIVE_RESTART_FIXED_INDEX).
constexpr uint32_t kRestartIndex = 0xffffffffu;

// Most segments a chord may stand for: bounds the work per point and how far a chord may cut across a
// long, gentle bend that stays within tolerance only on average.
constexpr uint32_t kMostSegmentsPerChord = 8;

// Every strand of two points or more as a line strip of indices into `strands`' points: its first and
// last points, and the points the greedy walk keeps so that every point it skips lies within
// `tolerance` (metres) of the chord that replaces it; each strip followed by kRestartIndex. Strips in
// strand order, or in `order` (strand indices, each of two points or more) when it is not empty.
// tolerance 0 keeps every point off a straight line. Deterministic, parallel over strands.
std::vector<uint32_t> decimatedLineStrips(const Strands& strands, double tolerance,
                                          const std::vector<uint32_t>& order = {});

}  // namespace hairgen
