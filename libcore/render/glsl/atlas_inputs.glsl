// In front of the hair's shading stage (hairgen's or a custom HairFrag) where it shades the camera's
// kept fragments (camera_fragments.h) one texel each of the shading atlas, drawn as one full-screen
// triangle over it: fragment j at column j mod the atlas' width, row j / its width. The stage's inputs
// are globals here (its `in` declarations of them are taken out: shader_interface.h), set before its
// main() runs to hair_vertex.glsl's outputs where the fragment lies along its segment, so the stage
// shades it as it would a line's fragment there. vAlpha is the fragment's coverage of its pixel times
// StrandOpacity. A texel past the last fragment is discarded.
layout(std430, binding = 0) readonly buffer HairgenPoints { float hairgenPointData[]; };
layout(std430, binding = 1) readonly buffer HairgenTangents { float hairgenTangentData[]; };
layout(std430, binding = 2) readonly buffer HairgenColors { float hairgenColorData[]; };
layout(std430, binding = 3) readonly buffer HairgenNormals { float hairgenNormalData[]; };
// Three words per fragment: its segment's first point, its depth (metres, a float's bits), its coverage
// and place along the segment (kCoverageBits).
layout(std430, binding = 5) readonly buffer HairgenFragments { uint hairgenFragmentData[]; };
uniform int hairgenHasColor;
uniform int hairgenHasNormal;
uniform float hairgenOpacity;        // StrandOpacity
uniform int hairgenAtlasWidth;       // texels
uniform int hairgenFragmentCount;    // at most the atlas' texels, fewer than 2^31
vec3 vWorld;
vec3 vTangent;
vec3 vColor;
vec3 vNormal;
float vAlpha;
float vDepth;
#define HAIRGEN_POINT(data, i) vec3(data[3 * (i)], data[3 * (i) + 1], data[3 * (i) + 2])
void hairgenShade();
void main() {
  int texel = int(gl_FragCoord.y) * hairgenAtlasWidth + int(gl_FragCoord.x);
  if (texel >= hairgenFragmentCount) discard;
  uint j = uint(texel);
  uint i = hairgenFragmentData[3u * j];
  uint word = hairgenFragmentData[3u * j + 2u];
  float coverage = float(word & ((1u << kCoverageBits) - 1u)) / float(kCoverageOne);
  float s = float(word >> kCoverageBits) / float(kSpanUnit);
  vWorld = mix(HAIRGEN_POINT(hairgenPointData, i), HAIRGEN_POINT(hairgenPointData, i + 1u), s);
  vTangent = mix(HAIRGEN_POINT(hairgenTangentData, i), HAIRGEN_POINT(hairgenTangentData, i + 1u), s);
  vColor = hairgenHasColor != 0
               ? mix(HAIRGEN_POINT(hairgenColorData, i), HAIRGEN_POINT(hairgenColorData, i + 1u), s)
               : vec3(1.0);
  vNormal = hairgenHasNormal != 0
                ? mix(HAIRGEN_POINT(hairgenNormalData, i), HAIRGEN_POINT(hairgenNormalData, i + 1u), s)
                : vec3(0.0);
  vAlpha = min(coverage * hairgenOpacity, 1.0);
  vDepth = uintBitsToFloat(hairgenFragmentData[3u * j + 1u]);
  hairgenShade();
}
#define main hairgenShade
