// The deep opacity map drawn by OpenGL, for a custom HairVert only (light_maps.h draws it otherwise): a
// line's fragment covers a texel by the strand's width in texels (at most 1), and adds that times its
// opacity to its layer and every layer behind it; one past the last layer counts in the last.
in float vDepth;
in float vAlpha;
// Where the hair begins, read as an image (image unit 0): the same float as a texel fetch, without the
// sampler's code in every fragment (~12% of the pass's rasteriser time on llvmpipe).
layout(binding = 0, r32f) uniform readonly image2D uStart;
uniform vec4 uLayers;
uniform float uFocalPx;  // texels per metre at one metre of depth
uniform float uWidth;    // strand diameter, metres
layout(location = 0) out vec4 oOpacity;
void main() {
  float z0 = imageLoad(uStart, ivec2(gl_FragCoord.xy)).r;
  vec4 ends = z0 + vec4(uLayers.x, uLayers.x + uLayers.y, uLayers.x + uLayers.y + uLayers.z,
                        uLayers.x + uLayers.y + uLayers.z + uLayers.w);
  float a = vAlpha * min(uWidth * uFocalPx / max(vDepth, 1e-6), 1.0);
  oOpacity = vec4(vDepth < ends.x ? a : 0.0, vDepth < ends.y ? a : 0.0, vDepth < ends.z ? a : 0.0, a);
}
