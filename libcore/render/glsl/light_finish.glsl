// The light's integer maps as the textures the shadow lookup reads (HairLightMaps::startMetres and
// ::opacity, the same arithmetic): where the hair begins in metres (uBackground where none reached), each
// layer's coverage times the strand's opacity.
layout(local_size_x = 256) in;
layout(std430, binding = 2) readonly buffer Start { int startData[]; };
layout(std430, binding = 3) buffer Layers { uint layerData[]; };
layout(std430, binding = 4) readonly buffer Overflow { uint overflowData[]; };
layout(r32f, binding = 0) uniform writeonly image2D uStartImage;
layout(rgba32f, binding = 1) uniform writeonly image2D uOpacityImage;
uniform int uSize;            // texels a side
uniform float uBackground;    // metres
uniform double uDepthUnit;    // kDepthUnit
uniform double uOpacityScale;  // StrandOpacity / kCoverageOne
// Layer k's sum, the largest where it passed a word (and written back so, for a caller reading them).
uint saturatedLayer(uint t, int k) {
  uint sum = (overflowData[t] & (1u << k)) != 0u ? 0xFFFFFFFFu : layerData[4u * t + uint(k)];
  layerData[4u * t + uint(k)] = sum;
  return sum;
}

void main() {
  uint t = (gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x) * gl_WorkGroupSize.x +
           gl_LocalInvocationID.x;
  if (t >= uint(uSize * uSize)) return;
  ivec2 at = ivec2(int(t) % uSize, int(t) / uSize);
  int start = startData[t];
  imageStore(uStartImage, at, vec4(start == 0x7FFFFFFF ? uBackground : float(double(start) * uDepthUnit)));
  // Each layer by name: NVIDIA's compiler (580) fails to link a dvec4 written at a run-time index.
  dvec4 sums = dvec4(double(saturatedLayer(t, 0)), double(saturatedLayer(t, 1)), double(saturatedLayer(t, 2)),
                     double(saturatedLayer(t, 3)));
  imageStore(uOpacityImage, at, vec4(sums * uOpacityScale));
}
