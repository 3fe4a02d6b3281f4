// Whether this device's floating point gives the CPU's bits where hairgen's compute passes use it
// (compute_raster.cpp: floatingPointAgrees): a depth in kDepthUnit as the float metres the passes compare
// and store, and the exact rounded square root. The probe draws no segment.
layout(std430, binding = 2) readonly buffer Depths { int depthData[]; };
layout(std430, binding = 3) readonly buffer Squares { uint64_t squareData[]; };
layout(std430, binding = 4) writeonly buffer Metres { uint metreData[]; };
layout(std430, binding = 5) writeonly buffer Roots { uint64_t rootData[]; };
uniform double uDepthUnit;
uniform uint uCount;
void emit(int column, int row, int depth, uint coverage, int64_t twice, int64_t length) {}
void main() {
  uint i = segmentOfInvocation();
  if (i >= uCount) return;
  metreData[i] = floatBitsToUint(float(double(depthData[i]) * uDepthUnit));
  rootData[i] = roundedSqrt(squareData[i]);
}
