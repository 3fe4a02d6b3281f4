// The camera's fragments on the device (camera_fragments.h), first pass: how many fragments each pixel
// gets (those the head hides are none). Their prefix sums (prefix_sum.glsl) are each pixel's place in
// the lists.
layout(binding = kUnitSubpixelData) uniform sampler2D uOpaque;  // R: the head's depth, metres
uniform int uHasOpaque;
uniform double uDepthUnit;  // kDepthUnit
layout(std430, binding = 2) buffer Counts { uint countData[]; };
void emit(int column, int row, int depth, uint coverage, int64_t twice, int64_t length) {
  if (uHasOpaque != 0 && float(double(depth) * uDepthUnit) >= texelFetch(uOpaque, ivec2(column, row), 0).r)
    return;
  atomicAdd(countData[row * uRasterSize.x + column], 1u);
}
void main() {
  uint s = segmentOfInvocation();
  if (s < uSegmentCount) rasteriseSegment(rasterSegments[s]);
}
