// The camera's fragments on the device, second pass, for the rows [uRowLo, uRowHi) (a slab that fits the
// device's buffers): each fragment into its pixel's list (its place among every pixel's, the prefix sum
// of the counts, less the slab's first), in whatever order the device runs them: the keeping pass sorts
// them.
layout(binding = kUnitSubpixelData) uniform sampler2D uOpaque;
uniform int uHasOpaque;
uniform double uDepthUnit;
uniform int uRowLo, uRowHi;
uniform uint uSlabFirst;  // the slab's first pixel's offset (sums modulo 2^32: a slab's are exact)
layout(std430, binding = 2) readonly buffer Offsets { uint offsetData[]; };  // among every pixel's
layout(std430, binding = 3) buffer Cursors { uint cursorData[]; };
// Per fragment: its segment's first point, its depth (kDepthUnit), its coverage, where along its segment
// (1/kSpanUnit).
layout(std430, binding = 4) writeonly buffer Lists { uvec4 listData[]; };
layout(std430, binding = 5) readonly buffer Counts { uint countData[]; };
uint gPoint;  // the segment being drawn
void emit(int column, int row, int depth, uint coverage, int64_t twice, int64_t length) {
  if (row < uRowLo || row >= uRowHi) return;
  if (uHasOpaque != 0 && float(double(depth) * uDepthUnit) >= texelFetch(uOpaque, ivec2(column, row), 0).r)
    return;
  int pixel = row * uRasterSize.x + column;
  // More than the count pass found would spill into the next pixel's list: dropped, and the keeping
  // pass reports the pixel (its cursor is not its count).
  uint k = atomicAdd(cursorData[pixel], 1u);
  if (k >= countData[pixel]) return;
  listData[offsetData[pixel] - uSlabFirst + k] = uvec4(gPoint, uint(depth), coverage, uint(twice * int64_t(kSpanUnit) / (2l * length)));
}
void main() {
  uint s = segmentOfInvocation();
  if (s >= uSegmentCount) return;
  gPoint = rasterSegments[s];
  rasteriseSegment(gPoint);
}
