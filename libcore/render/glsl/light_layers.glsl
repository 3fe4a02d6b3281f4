// The light's deep opacity layers on the device (light_maps.h): each fragment's coverage added to its
// layer, measured from where the hair begins, and to every layer behind it. Integer sums, the same
// whatever order they come in; a sum past a word's largest is flagged and read as that largest, as the
// CPU's saturating sums are.
layout(std430, binding = 2) readonly buffer Start { int startData[]; };
layout(std430, binding = 3) buffer Layers { uint layerData[]; };       // four per texel
layout(std430, binding = 4) buffer Overflow { uint overflowData[]; };  // bit k: layer k passed 2^32
uniform ivec3 uLayerEnds;  // the first three layers' far ends behind where the hair begins, kDepthUnit
void add(int texel, int k, uint coverage) {
  uint before = atomicAdd(layerData[4 * texel + k], coverage);
  if (coverage > 0xFFFFFFFFu - before) atomicOr(overflowData[texel], 1u << k);
}
void emit(int column, int row, int depth, uint coverage, int64_t twice, int64_t length) {
  int texel = row * uRasterSize.x + column;
  int64_t behind = int64_t(depth) - int64_t(startData[texel]);
  for (int k = 0; k < 3; ++k)
    if (behind < int64_t(uLayerEnds[k])) add(texel, k, coverage);
  add(texel, 3, coverage);
}
void main() {
  uint s = segmentOfInvocation();
  if (s < uSegmentCount) rasteriseSegment(rasterSegments[s]);
}
