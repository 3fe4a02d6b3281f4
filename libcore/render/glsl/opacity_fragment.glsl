// The deep opacity map: a fragment adds its opacity to its layer and every layer behind it; one past
// the last layer counts in the last.
in float vDepth;
in float vAlpha;
// Where the hair begins, read as an image (image unit 0): the same float as a texel fetch, without the
// sampler's code in every fragment (~12% of the pass's rasteriser time on llvmpipe).
layout(binding = 0, r32f) uniform readonly image2D uStart;
uniform vec4 uLayers;
layout(location = 0) out vec4 oOpacity;
void main() {
  float z0 = imageLoad(uStart, ivec2(gl_FragCoord.xy)).r;
  vec4 ends = z0 + vec4(uLayers.x, uLayers.x + uLayers.y, uLayers.x + uLayers.y + uLayers.z,
                        uLayers.x + uLayers.y + uLayers.z + uLayers.w);
  float a = vAlpha;
  oOpacity = vec4(vDepth < ends.x ? a : 0.0, vDepth < ends.y ? a : 0.0, vDepth < ends.z ? a : 0.0, a);
}
