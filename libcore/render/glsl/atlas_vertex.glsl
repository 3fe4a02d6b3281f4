// hairgen's vertex stage for the camera's kept fragments (camera_fragments.h): one point per fragment,
// at its own texel of the shading atlas (fragment j at column j mod uAtlasWidth, row j / uAtlasWidth),
// with hair_vertex.glsl's outputs taken where the fragment lies along its segment, so the hair's
// fragment stage (hairgen's or a custom HairFrag) shades it as it would a line's fragment there. vAlpha
// is the fragment's coverage of its pixel times the strand's opacity.
layout(std430, binding = 0) readonly buffer Points { float pointData[]; };
layout(std430, binding = 1) readonly buffer Tangents { float tangentData[]; };
layout(std430, binding = 2) readonly buffer Colors { float colorData[]; };
layout(std430, binding = 3) readonly buffer Normals { float normalData[]; };
// Three words per fragment: its segment's first point, its depth (metres, a float's bits), its coverage
// and place along the segment (kCoverageBits).
layout(std430, binding = 5) readonly buffer Fragments { uint fragmentData[]; };
uniform int uHasColor;
uniform int uHasNormal;
uniform float uOpacity;    // StrandOpacity
uniform int uAtlasWidth;   // texels
uniform vec2 uAtlasSize;   // texels
out vec3 vWorld;
out vec3 vTangent;
out vec3 vColor;
out vec3 vNormal;
out float vAlpha;
out float vDepth;
#define POINT_DATA(data, i) vec3(data[3 * (i)], data[3 * (i) + 1], data[3 * (i) + 2])
void main() {
  int j = gl_VertexID;
  int i = int(fragmentData[3 * j]);
  uint word = fragmentData[3 * j + 2];
  float coverage = float(word & ((1u << kCoverageBits) - 1u)) / float(kCoverageOne);
  float s = float(word >> kCoverageBits) / float(kSpanUnit);
  vWorld = mix(POINT_DATA(pointData, i), POINT_DATA(pointData, i + 1), s);
  vTangent = mix(POINT_DATA(tangentData, i), POINT_DATA(tangentData, i + 1), s);
  vColor = uHasColor != 0 ? mix(POINT_DATA(colorData, i), POINT_DATA(colorData, i + 1), s) : vec3(1.0);
  vNormal = uHasNormal != 0 ? mix(POINT_DATA(normalData, i), POINT_DATA(normalData, i + 1), s) : vec3(0.0);
  vAlpha = min(coverage * uOpacity, 1.0);
  vDepth = uintBitsToFloat(fragmentData[3 * j + 1]);
  vec2 texel = vec2(j % uAtlasWidth, j / uAtlasWidth) + 0.5;
  gl_Position = vec4(texel / uAtlasSize * 2.0 - 1.0, 0.0, 1.0);
}
