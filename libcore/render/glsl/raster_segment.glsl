// hairgen's hair rasteriser's segment (hair_raster.h: rasteriseSegment), the same integer arithmetic
// in GLSL for the compute passes, so a GPU and the CPU find the same fragments to the bit. A pass
// defines ACROSS_TENT for the tent filter across (the light's maps; the box otherwise), declares
// `void emit(int column, int row, int depth, uint coverage, int64_t twice, int64_t length)` (a
// fragment on the image, coverage > 0) and calls rasteriseSegment for the segment it draws.
// Needs GL_ARB_gpu_shader_int64 and the raster constants (compute_raster.cpp). One segment an
// invocation, 256 a group.
layout(local_size_x = 256) in;
layout(std430, binding = kRasterVertexBinding) readonly buffer RasterVertices { ivec4 rasterVertices[]; };
layout(std430, binding = kRasterSegmentBinding) readonly buffer RasterSegments { uint rasterSegments[]; };
uniform ivec2 uRasterSize;    // the image's texels
uniform uint uSegmentCount;   // rasterSegments' length

void emit(int column, int row, int depth, uint coverage, int64_t twice, int64_t length);

// ⌊a / b⌋ for b > 0 (GLSL leaves negative division to the implementation).
int64_t floorDiv(int64_t a, int64_t b) {
  return a >= 0l ? a / b : -((-a + b - 1l) / b);
}

// hair_raster.h's roundedSqrt: the estimate only starts the integer search (GLSL leaves a double sqrt's
// precision to the device), kept below 2^27 (n < 2^54) so the squares cannot overflow.
uint64_t roundedSqrt(uint64_t n) {
  uint64_t r = min(uint64_t(sqrt(double(n))), 1ul << 27);
  while (r > 0ul && r * r > n) --r;
  while ((r + 1ul) * (r + 1ul) <= n) ++r;
  return n - r * r > r ? r + 1ul : r;
}

// (x · y) >> 40 of the 128-bit product, its low 64 bits (as the CPU's Uint128 is truncated).
uint64_t mulShift40(uint64_t x, uint64_t y) {
  const uint64_t mask = 0xFFFFFFFFul;
  uint64_t xl = x & mask, xh = x >> 32, yl = y & mask, yh = y >> 32;
  uint64_t ll = xl * yl, lh = xl * yh, hl = xh * yl, hh = xh * yh;
  uint64_t mid = (ll >> 32) + (lh & mask) + (hl & mask);
  uint64_t low = (mid << 32) | (ll & mask);
  uint64_t high = hh + (lh >> 32) + (hl >> 32) + (mid >> 32);
  return (high << 24) | (low >> 40);
}

// hair_raster.h's MidpointStep: base + ⌊d·t / (2n)⌋ stepped by t += 2·kSubTexel.
struct MidpointStep {
  int64_t den, q, r, stepQ, stepR;
};
MidpointStep midpointStep(int64_t base, int64_t d, int64_t n, int64_t t0) {
  MidpointStep s;
  s.den = 2l * n;
  s.q = floorDiv(d * t0, s.den);
  s.r = d * t0 - s.q * s.den;
  s.q += base;
  s.stepQ = floorDiv(2l * kSubTexel * d, s.den);
  s.stepR = 2l * kSubTexel * d - s.stepQ * s.den;
  return s;
}
void advance(inout MidpointStep s) {
  s.q += s.stepQ;
  s.r += s.stepR;
  if (s.r >= s.den) {
    s.r -= s.den;
    ++s.q;
  }
}

#ifdef ACROSS_TENT
int64_t tentIntegral(int64_t x) {
  const int64_t k = kSubTexel;
  if (x <= -k) return 0l;
  if (x >= k) return 2l * k * k;
  return x < 0l ? (x + k) * (x + k) : 2l * k * k - (k - x) * (k - x);
}
#endif

int64_t acrossShare(int64_t m, int64_t below, int64_t above) {
  const int64_t start = m * kSubTexel;
#ifdef ACROSS_TENT
  const int64_t centre = start + kSubTexel / 2l;
  return tentIntegral(above - centre) - tentIntegral(below - centre);
#else
  return max(0l, min(above, start + kSubTexel) - max(below, start));
#endif
}

int64_t acrossTotal(int64_t extent) {
#ifdef ACROSS_TENT
  return 2l * kSubTexel * extent;
#else
  return extent;
#endif
}

// The segment from point `first` to the next, every fragment on the image emitted.
void rasteriseSegment(uint first) {
  ivec4 a = rasterVertices[first], b = rasterVertices[first + 1u];
  const bool alongX = abs(int64_t(b.x) - int64_t(a.x)) >= abs(int64_t(b.y) - int64_t(a.y));
  const bool reversed = alongX ? a.x > b.x : a.y > b.y;
  if (reversed) {
    ivec4 t = a;
    a = b;
    b = t;
  }
  const int64_t u0 = alongX ? a.x : a.y, u1 = alongX ? b.x : b.y, v0 = alongX ? a.y : a.x;
  const int64_t du = u1 - u0, dv = int64_t(alongX ? b.y : b.x) - v0, dz = int64_t(b.z) - int64_t(a.z);
  if (du == 0l) return;
  const uint64_t length = roundedSqrt(uint64_t(du * du + dv * dv));
  const uint64_t width = (uint64_t(uint(a.w)) + uint64_t(uint(b.w))) / 2ul;
  const uint64_t extent = width * length / uint64_t(du);
  const uint64_t perSub = uint64_t(kWidthUnit / kSubTexel);
  const int64_t halfExtent = max(1l, int64_t((extent + perSub) / (2ul * perSub)));
  const uint64_t perExtent = (1ul << 40) / uint64_t(acrossTotal(2l * halfExtent));
  // The texels along the major axis, those on the image only (a fragment off it is dropped anyway).
  const int64_t along = alongX ? int64_t(uRasterSize.x) : int64_t(uRasterSize.y);
  const int64_t first0 = max(u0 >> 8, 0l), last = min((u1 - 1l) >> 8, along - 1l);
  const int64_t acrossSize = alongX ? int64_t(uRasterSize.y) : int64_t(uRasterSize.x);
  const int64_t reach = int64_t(extent / (2ul * perSub)) + 2l * kSubTexel;
  // A segment whose cross-section cannot reach the image across (the piece's middles lie between its
  // ends) has no fragment on it.
  if (max(v0, v0 + dv) + reach < 0l || min(v0, v0 + dv) - reach >= acrossSize * kSubTexel) return;
  const uint64_t perArea = uint64_t(du) * uint64_t(kWidthUnit * kSubTexel / int64_t(kCoverageOne));
  const uint64_t wholeArea = (width * uint64_t(kSubTexel) * length + perArea / 2ul) / perArea;
  const int64_t twiceFirst = 2l * first0 * kSubTexel + kSubTexel - 2l * u0;
  MidpointStep vStep = midpointStep(v0, dv, du, twiceFirst);
  MidpointStep depthStep = midpointStep(int64_t(a.z), dz, du, twiceFirst);
  const int64_t reachOut = acrossTotal(1l) == 1l ? 0l : kSubTexel / 2l;
  for (int64_t c = first0; c <= last; ++c) {
    const int64_t lo = max(u0, c * kSubTexel), hi = min(u1, (c + 1l) * kSubTexel);
    if (hi > lo) {
      const bool whole = hi - lo == kSubTexel;
      const int64_t twice = lo + hi - 2l * u0;
      const int64_t v = whole ? vStep.q : v0 + floorDiv(dv * twice, 2l * du);
      const int depth = int(whole ? depthStep.q : int64_t(a.z) + floorDiv(dz * twice, 2l * du));
      const uint64_t area =
          whole ? wholeArea : (width * uint64_t(hi - lo) * length + perArea / 2ul) / perArea;
      const int64_t pieceTwice = reversed ? 2l * du - twice : twice;
      const int64_t below = v - halfExtent, above = v + halfExtent;
      const int64_t mFirst = floorDiv(below - reachOut, kSubTexel);
      const int64_t mLast = floorDiv(above + reachOut - 1l, kSubTexel);
      uint64_t given = 0ul;
      for (int64_t m = mFirst; m <= mLast; ++m) {
        uint64_t share = area - given;
        if (m < mLast) share = mulShift40(area * uint64_t(acrossShare(m, below, above)), perExtent);
        given += share;
        if (uint(share) != 0u && m >= 0l && m < acrossSize)
          emit(int(alongX ? c : m), int(alongX ? m : c), depth, uint(share), pieceTwice, du);
      }
    }
    advance(vStep);
    advance(depthStep);
  }
}

// The segment this invocation draws (dispatched as rows of groups: computeGroups), or none past the end.
uint segmentOfInvocation() {
  return (gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x) * gl_WorkGroupSize.x +
         gl_LocalInvocationID.x;
}
