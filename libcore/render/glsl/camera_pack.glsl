// The camera's fragments on the device, last pass: each pixel's kept fragments from its place in Staging
// into CameraFragments' layout, three words each from the pixel's first (the prefix sum of the kept
// counts).
layout(local_size_x = 256) in;
layout(std430, binding = 0) readonly buffer First { uint firstData[]; };
layout(std430, binding = 1) writeonly buffer Words { uint wordData[]; };
layout(std430, binding = 2) readonly buffer KeepAt { uint keepAtData[]; };
layout(std430, binding = 3) readonly buffer Staging { uint stagingData[]; };
uniform uint uPixels;
void main() {
  uint p = (gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x) * gl_WorkGroupSize.x +
           gl_LocalInvocationID.x;
  if (p >= uPixels) return;
  uint from = 3u * keepAtData[p], to = 3u * firstData[p], n = 3u * (firstData[p + 1u] - firstData[p]);
  for (uint k = 0u; k < n; ++k) wordData[to + k] = stagingData[from + k];
}
