// hairgen's own hair rasteriser, shared by the light's maps (light_maps.h) and the camera's view
// (camera_fragments.h), so both see a strand with the same arithmetic on every machine.
//
// Every point is projected once in double precision and quantised: window x and y to 1/kSubTexel of a
// texel (or pixel), depth along the view's axis to kDepthUnit, the strand's projected width to
// 1/kWidthUnit of a texel. From there on everything is integer arithmetic. Each segment is a thin
// ribbon of the strand's width (Kajiya & Kay's cylinder seen from the view), cut at the texel
// boundaries along its major axis (x or y, whichever it moves more along): each piece covers the
// strand's width × its true length within that texel column (or row), exactly. Across, the piece's
// cross-section (the ribbon's extent there) is shared among the texels by a filter (Across): each
// texel's box, so a texel gets the area of the ribbon that lies in it (the camera's analytic
// coverage), or a tent one texel either side of each texel centre, smoother still (the light's maps,
// which a shadow lookup then interpolates). Either way the filters sum to one everywhere, so the shares
// sum to the piece's area (the last takes the rounding), the inside of a strand wider than a texel is
// covered exactly once, and what is drawn changes continuously as a strand moves, however thin. Pure
// math: no OpenGL.
//
// The image is cut into bands of kBandRows rows, each segment listed in every band it can reach, in
// the order of its first point; a caller draws each band on one thread, its segments in that order, so
// what it keeps does not depend on the thread count.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "libcore/model/strands.h"
#include "libcore/render/views.h"

namespace hairgen {

// Window positions are kept in 1/kSubTexel texel: 8 bits of sub-texel position, as GPUs snap vertices.
inline constexpr int kSubTexelBits = 8;
inline constexpr int kSubTexel = 1 << kSubTexelBits;
// A strand's projected width in 1/kWidthUnit texel, so a strand a tenth of a texel wide covers what it
// should to 0.2% (products with a length in 1/kSubTexel still fit in 64 bits).
inline constexpr int kWidthUnit = 1 << 16;
// 1/kWidthUnit texel in 1/kSubTexel texel.
inline constexpr int kWidthPerSub = kWidthUnit / kSubTexel;
// Depth along the view's axis in whole micrometres: a 40 µm strand is 40 units, and 2^31 units reach
// 2 km.
inline constexpr double kDepthUnit = 1.0e-6;
// A texel fully covered once, in coverage units.
inline constexpr uint32_t kCoverageOne = 1u << 16;

namespace raster {

inline constexpr int kBandRows = 32;  // rows a thread draws at once
// How many segments ahead a band's drawing asks for the vertices it will read: a band's segments are a
// sparse subset of the points (a thirtieth at 1080p), so each segment's vertices would otherwise be a
// cache miss the prefetcher cannot foresee (15% of the camera's fragments' time).
inline constexpr size_t kPrefetch = 16;

// A share's product needs 76 bits: GCC's and Clang's 128-bit integer (one multiply on x86-64).
__extension__ using Uint128 = unsigned __int128;

// Rounds toward −∞, so positions left of and right of 0 are split into texels alike.
inline int64_t floorDiv(int64_t a, int64_t b) {
  const int64_t q = a / b;
  return (a % b != 0 && ((a < 0) != (b < 0))) ? q - 1 : q;
}

// A point as the rasteriser reads it: x, y in 1/kSubTexel texel (window, y up), depth in kDepthUnit,
// the strand's projected width in 1/kWidthUnit texel; depth −1 when the point is not drawn.
struct Vertex {
  int32_t x, y, depth, width;
};

// Where a fragment's piece lies along its segment: its middle at twice / (2·length) of the way from
// the segment's first point, both along the major axis in 1/kSubTexel.
struct Piece {
  int64_t twice, length;
};

// ⌊n / d⌋ for many n and one d > 0, exactly, without a division each: a double's reciprocal gives the
// quotient to within one (|n| < 2^63 and a quotient below 2^50, as the rasteriser's are) and integers
// correct it without a branch. A segment and its pieces divide by its length along the major axis a
// dozen times: as integer divisions whose rounding toward zero was mended by a branch on the sign, the
// light's and the camera's rasterisers took 22% and 27% longer on the 1080p coupe's short segments.
class Divider {
 public:
  explicit Divider(int64_t d) : Divider(d, 1.0 / double(d)) {}
  // `reciprocal`: 1/d rounded, as 1.0 / double(d) gives it (or that of d/2^k scaled by 2^-k, which is
  // the same double).
  Divider(int64_t d, double reciprocal) : d_(d), reciprocal_(reciprocal) {}
  int64_t floor(int64_t n) const {
    int64_t q = int64_t(double(n) * reciprocal_);  // truncated: one more or less than ⌊n/d⌋ at most
    int64_t r = n - q * d_;
    // Corrected without a branch: which way it is off changes with the sign of n, segment by segment.
    const int64_t over = r >> 63;  // −1 where q is one too many
    q += over;
    r += d_ & over;
    const int64_t under = -int64_t(r >= d_);
    q -= under;
    r -= d_ & under;
    if (r < 0 || r >= d_) [[unlikely]]  // never for the rasteriser's quotients (|q| < 2^50)
      return floorDiv(n, d_);
    return q;
  }
  // ⌊n / d⌋ and what remains of n, for n ≥ 0 below 2^63.
  uint64_t floor(uint64_t n, uint64_t& remainder) const {
    const int64_t q = floor(int64_t(n));
    remainder = n - uint64_t(q) * uint64_t(d_);
    return uint64_t(q);
  }
  int64_t divisor() const { return d_; }
  double reciprocal() const { return reciprocal_; }

 private:
  int64_t d_;
  double reciprocal_;
};

// base + ⌊d·t / (2n)⌋ for t = t0, t0 + 2·kSubTexel, t0 + 4·kSubTexel, …: exact, with no division after
// the first (`twoN` divides by 2n).
class MidpointStep {
 public:
  MidpointStep(int64_t base, int64_t d, const Divider& twoN, int64_t t0) : den_(twoN.divisor()) {
    q_ = twoN.floor(d * t0);
    r_ = d * t0 - q_ * den_;
    q_ += base;
    stepQ_ = twoN.floor(2 * kSubTexel * d);
    stepR_ = 2 * kSubTexel * d - stepQ_ * den_;
  }
  int64_t value() const { return q_; }
  void next() {
    r_ += stepR_;
    const int64_t carry = -int64_t(r_ >= den_);  // without a branch: it follows the slope
    q_ += stepQ_ - carry;
    r_ -= den_ & carry;
  }

 private:
  int64_t den_, q_, r_, stepQ_, stepR_;
};

// √n rounded to the nearest integer, exactly (never a tie: (r + ½)² is no integer), so every machine
// and the GLSL twin (glsl/raster_segment.glsl) agree: a floating-point estimate corrected in integers.
inline uint64_t roundedSqrt(uint64_t n) {
  uint64_t r = std::min<uint64_t>(uint64_t(std::sqrt(double(n))), uint64_t(1) << 27);  // n < 2^54
  while (r > 0 && r * r > n) --r;
  while ((r + 1) * (r + 1) <= n) ++r;
  return n - r * r > r ? r + 1 : r;  // n ≥ r² + r + 1 > (r + ½)²
}

// Coverage sums stop at the largest a word holds, however many strands pile into a texel.
inline void addSaturating(uint32_t& sum, uint32_t add) {
  sum = add > UINT32_MAX - sum ? UINT32_MAX : sum + add;
}

// How a piece's cross-section is shared among the texels across it (above).
enum class Across { kBox, kTent };

// The share of the cross-section [below, above] (1/kSubTexel texel) that texel m's filter holds, and
// what every texel's shares sum to.
template <Across across>
int64_t acrossShare(int64_t m, int64_t below, int64_t above) {
  const int64_t start = m * kSubTexel;
  if constexpr (across == Across::kBox) {
    return std::max<int64_t>(0, std::min(above, start + kSubTexel) - std::max(below, start));
  } else {
    // 2·kSubTexel² × the integral of the tent 1 − |u| (u in texels from the centre) up to x.
    auto integral = [](int64_t x) -> int64_t {
      if (x <= -kSubTexel) return 0;
      if (x >= kSubTexel) return 2 * kSubTexel * kSubTexel;
      return x < 0 ? (x + kSubTexel) * (x + kSubTexel)
                   : 2 * kSubTexel * kSubTexel - (kSubTexel - x) * (kSubTexel - x);
    };
    const int64_t centre = start + kSubTexel / 2;
    return integral(above - centre) - integral(below - centre);
  }
}
template <Across across>
constexpr int64_t acrossTotal(int64_t extent) {
  return across == Across::kBox ? extent : 2 * kSubTexel * extent;
}

// Calls fragment(column, row, depth, coverage, piece) for each texel the segment a → b covers,
// coverage in kCoverageOne per texel; `rowLo`, `rowHi`: the rows wanted (others may come too). Along
// the segment's major axis it is cut at the texel boundaries: a piece of length o along that axis
// covers the strand's width × its true length, w·o·L/|du|, exactly. Across, the piece's cross-section,
// its extent w·L/|du| about the piece's middle, is shared among the texels by `across`. Which
// fragments a segment has does not depend on the rows asked for.
template <Across across, class F>
void rasteriseSegment(Vertex a, Vertex b, int64_t rowLo, int64_t rowHi, F&& fragment) {
  // A piece's area w·o·L/|du| (1/(kWidthUnit·kSubTexel) texel²) is in kCoverageOne per texel² over
  // kSubTexel·du.
  static_assert(kWidthUnit == kCoverageOne);
  const bool alongX = std::abs(int64_t(b.x) - a.x) >= std::abs(int64_t(b.y) - a.y);
  auto major = [&](const Vertex& v) { return int64_t(alongX ? v.x : v.y); };
  auto minor = [&](const Vertex& v) { return int64_t(alongX ? v.y : v.x); };
  const bool reversed = major(a) > major(b);
  if (reversed) std::swap(a, b);
  const int64_t u0 = major(a), u1 = major(b), v0 = minor(a);
  const int64_t du = u1 - u0, dv = minor(b) - v0, dz = int64_t(b.depth) - a.depth;
  if (du == 0) return;  // seen end on: no length, no area
  // Every quotient below is by 2·du (or kSubTexel·du): one reciprocal for all of them (Divider).
  const Divider twoDu(2 * du);
  // Rounded to the nearest 1/kSubTexel, so short segments are not all a little short.
  const uint64_t length = roundedSqrt(uint64_t(du * du + dv * dv));
  const uint64_t width = (uint64_t(a.width) + uint64_t(b.width)) / 2;  // 1/kWidthUnit texel
  // The ribbon's extent across the major axis, ⌊w·L/|du|⌋ in 1/kWidthUnit texel, and a whole texel's
  // piece's area, w·L/|du| rounded to kCoverageOne per texel² (w·kSubTexel·L over kSubTexel·du: the
  // same quotient, rounded half up).
  uint64_t twiceRest;  // 2·(w·L mod du)
  const uint64_t extent = twoDu.floor(2 * width * length, twiceRest);
  const uint64_t wholeArea = extent + (twiceRest >= uint64_t(du) ? 1 : 0);
  // Half the extent in 1/kSubTexel, at least one (a thinner ribbon is shared as a line is).
  const int64_t halfExtent = std::max<int64_t>(1, int64_t((extent + kWidthPerSub) / (2 * kWidthPerSub)));
  // The reciprocal of what the shares of the cross-section sum to, in 1/2^40, so a texel's part of a
  // piece's area is a multiplication and a shift.
  const uint64_t perExtent = (uint64_t(1) << 40) / uint64_t(acrossTotal<across>(2 * halfExtent));
  // The texels along the major axis, [first, last], narrowed to those that can reach the rows.
  int64_t first = u0 >> kSubTexelBits, last = (u1 - 1) >> kSubTexelBits;
  const int64_t reach = int64_t(extent / (2 * kWidthPerSub)) + 2 * kSubTexel;
  if (!alongX) {
    first = std::max(first, rowLo);
    last = std::min(last, rowHi - 1);
  } else if (const int64_t vLow = std::min(v0, v0 + dv) - reach, vHigh = std::max(v0, v0 + dv) + reach;
             vHigh < rowLo * kSubTexel || vLow >= rowHi * kSubTexel) {
    return;
  } else if (dv != 0 && (vLow < rowLo * kSubTexel || vHigh >= rowHi * kSubTexel)) {
    // v at a piece's middle is v0 + dv·(u − u0)/du; found in double with two texels to spare either
    // side (a texel whose fragments fall outside the rows is dropped by the caller). A segment whose
    // reach lies within the rows keeps every texel.
    double c0 =
        (double(u0) + (double(rowLo * kSubTexel - reach) - double(v0)) * double(du) / double(dv)) / kSubTexel;
    double c1 =
        (double(u0) + (double(rowHi * kSubTexel + reach) - double(v0)) * double(du) / double(dv)) / kSubTexel;
    if (c0 > c1) std::swap(c0, c1);
    if (c0 > double(last) + 2.0 || c1 < double(first) - 2.0) return;
    first = std::max(first, int64_t(std::floor(c0)) - 2);
    last = std::min(last, int64_t(std::ceil(c1)) + 2);
  }
  // A piece cut by the segment's end: its area w·o·L/|du| rounded, over kSubTexel·du.
  const Divider perArea(kSubTexel * du, twoDu.reciprocal() / (kSubTexel / 2));
  const uint64_t widthLength = width * length;
  // A whole texel's piece's middle's v and depth stepped from texel to texel (the middle moves
  // 2·kSubTexel in `twice` a texel); a piece cut by the segment's end is computed on its own.
  const int64_t twiceFirst = 2 * first * kSubTexel + kSubTexel - 2 * u0;
  MidpointStep vStep(v0, dv, twoDu, twiceFirst), depthStep(a.depth, dz, twoDu, twiceFirst);
  constexpr int64_t reachOut = across == Across::kBox ? 0 : kSubTexel / 2;
  for (int64_t c = first; c <= last; ++c, vStep.next(), depthStep.next()) {
    const int64_t lo = std::max(u0, c * kSubTexel), hi = std::min(u1, (c + 1) * kSubTexel);
    if (hi <= lo) continue;
    const bool whole = hi - lo == kSubTexel;
    // The piece's middle, as a fraction of the segment: (lo + hi − 2·u0) / (2·du).
    const int64_t twice = lo + hi - 2 * u0;
    const int64_t v = whole ? vStep.value() : v0 + twoDu.floor(dv * twice);
    const int32_t depth = int32_t(whole ? depthStep.value() : a.depth + twoDu.floor(dz * twice));
    // w·o·L/|du|: 1/(kWidthUnit·kSubTexel) texel², to kCoverageOne per texel², rounded.
    const uint64_t area = whole ? wholeArea
                                : uint64_t(perArea.floor(int64_t(widthLength * uint64_t(hi - lo) +
                                                                 kSubTexel / 2 * uint64_t(du))));
    // Where the piece lies from the caller's first point (the points were swapped when reversed).
    const Piece piece{reversed ? 2 * du - twice : twice, du};
    // The texels across whose filters reach the cross-section [v − halfExtent, v + halfExtent].
    const int64_t below = v - halfExtent, above = v + halfExtent;
    const int64_t mFirst = (below - reachOut) >> kSubTexelBits;  // ⌊·/kSubTexel⌋
    const int64_t mLast = (above + reachOut - 1) >> kSubTexelBits;
    // Texel m's share of the piece's area, and the fragment it makes (the last texel across takes
    // what the others left, so the shares sum to the area).
    auto shareOf = [&](int64_t m) {
      return uint64_t(Uint128(area * uint64_t(acrossShare<across>(m, below, above))) * perExtent >> 40);
    };
    auto emit = [&](int64_t m, uint64_t share) {
      if (alongX)
        fragment(c, m, depth, uint32_t(share), piece);
      else
        fragment(m, c, depth, uint32_t(share), piece);
    };
    uint64_t given = 0;
    if (!alongX || (mFirst >= rowLo && mLast < rowHi)) {  // every texel across wanted: most pieces
      for (int64_t m = mFirst; m < mLast; ++m) {
        const uint64_t share = shareOf(m);
        given += share;
        emit(m, share);
      }
      emit(mLast, area - given);
      continue;
    }
    // Along x the texels across are rows, and those outside [rowLo, rowHi) are not wanted. Every texel
    // whose filter lies inside the cross-section, [insideFirst, insideLast], holds the same share, so a
    // run of unwanted ones is passed over with their shares' sum: `given` as adding them one by one
    // leaves it, so the wanted texels' shares are the same bits, and a strand thousands of texels wide
    // costs a band its rows, not its width.
    const int64_t insideFirst = -((-(below + reachOut)) >> kSubTexelBits);  // ⌈·/kSubTexel⌉
    const int64_t insideLast = ((above - reachOut) >> kSubTexelBits) - 1;
    for (int64_t m = mFirst; m <= mLast; ++m) {
      if ((m < rowLo || m >= rowHi) && m >= insideFirst && m <= insideLast && m < mLast) {
        const int64_t next = std::min({m < rowLo ? rowLo : mLast, insideLast + 1, mLast});  // not passed over
        const uint64_t insideShare =  // asked for only here: most pieces have no run to pass over
            uint64_t(Uint128(area * uint64_t(acrossTotal<across>(kSubTexel))) * perExtent >> 40);
        given += uint64_t(next - m) * insideShare;
        m = next - 1;
        continue;
      }
      const uint64_t share = m < mLast ? shareOf(m) : area - given;
      given += share;
      emit(m, share);
    }
  }
}

// A box, in 1/kSubTexel texel, holding every texel a segment a → b has a fragment in: its points' box
// widened by the reach bandsOf uses for rows (hair_raster.cpp), at least half the ribbon's extent.
inline int64_t segmentReach(const Vertex& a, const Vertex& b) {
  return int64_t(std::max(a.width, b.width)) * 3 / (4 * (kWidthUnit / kSubTexel)) + 2 * kSubTexel;
}

// The hair as a view sees it, quantised: every point, and the segments drawn.
struct Projection {
  int width = 0, height = 0;       // the image's texels
  std::vector<Vertex> vertices;    // one per point
  std::vector<uint32_t> segments;  // each segment's first point, in order: both its points drawn
};

// The hair as a view sees it, quantised, and its segments sorted into bands of rows.
struct Bands {
  int width = 0, height = 0, count = 0;  // the image's texels; bands of kBandRows rows
  std::vector<Vertex> vertices;          // one per point
  std::vector<size_t> bandFirst;         // band b's segments: bandSegments[bandFirst[b], bandFirst[b + 1])
  std::vector<uint32_t> bandSegments;    // the segments' first points, in order within each band

  // Calls fragment(texel, depth, coverage, segment's first point, piece) for every fragment of every
  // segment of `band` that falls on the image within the band's rows, in the order of the segments;
  // texel = row · width + column. `unwanted(a, b)`: true for a segment a → b none of whose fragments
  // the caller would keep (it is not drawn: what the caller gets does not change).
  template <Across across, class F>
  void eachFragment(int band, F&& fragment) const {
    eachFragment<across>(band, fragment, [](const Vertex&, const Vertex&) { return false; });
  }
  template <Across across, class F, class U>
  void eachFragment(int band, F&& fragment, U&& unwanted) const {
    const int64_t rowLo = int64_t(band) * kBandRows, rowHi = std::min<int64_t>(height, rowLo + kBandRows);
    const size_t end = bandFirst[size_t(band) + 1];
    for (size_t k = bandFirst[size_t(band)]; k < end; ++k) {
      if (k + kPrefetch < end) {
        const Vertex* ahead = &vertices[bandSegments[k + kPrefetch]];
        __builtin_prefetch(ahead);
        __builtin_prefetch(ahead + 1);  // in the next cache line one time in four
      }
      const uint32_t point = bandSegments[k];
      if (unwanted(vertices[point], vertices[point + 1])) continue;
      rasteriseSegment<across>(vertices[point], vertices[point + 1], rowLo, rowHi,
                               [&](int64_t i, int64_t j, int32_t depth, uint32_t coverage, Piece piece) {
                                 if (coverage == 0 || j < rowLo || j >= rowHi || i < 0 || i >= width) return;
                                 fragment(size_t(j) * size_t(width) + size_t(i), depth, coverage, point,
                                          piece);
                               });
    }
  }
};

// Projects the hair with `v` (its width × height texels). `strandWidth`: the strands' diameter, metres.
// A segment with a point nearer than the near plane, or far off the image, is dropped. `reuse`: bands no
// longer needed (another view's of the same hair), whose storage is reused: its pages are already the
// process's, not faulted in and cleared by the kernel again.
Projection project(const Strands& hair, const View& v, double strandWidth, Bands reuse = {});

// The projection's segments sorted into bands (its vertices move into them).
Bands intoBands(Projection&& p);

// project(), then intoBands().
Bands projectIntoBands(const Strands& hair, const View& v, double strandWidth, Bands reuse = {});

}  // namespace raster

}  // namespace hairgen
