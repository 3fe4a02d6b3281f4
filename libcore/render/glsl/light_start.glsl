// The light's first map on the device (light_maps.h): per texel, the depth where the hair begins, the
// nearest of its fragments (an integer minimum: the same whatever order they come in).
layout(std430, binding = 2) buffer Start { int startData[]; };
void emit(int column, int row, int depth, uint coverage, int64_t twice, int64_t length) {
  atomicMin(startData[row * uRasterSize.x + column], depth);
}
void main() {
  uint s = segmentOfInvocation();
  if (s < uSegmentCount) rasteriseSegment(rasterSegments[s]);
}
