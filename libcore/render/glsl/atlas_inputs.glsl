// In front of the hair's shading stage (hairgen's or a custom HairFrag) where it shades the camera's
// kept fragments (camera_fragments.h) one texel each of the shading atlas, drawn as one full-screen
// triangle over it: fragment j at column j mod the atlas' width, row j / its width. The stage's `in`
// declarations of its inputs are made plain globals and its main() is renamed hairgenShade (below);
// the main() hairgen puts after the stage (shader_interface.cpp) sets those globals with
// hairgenInputs() to hair_vertex.glsl's outputs where the fragment lies along its segment, so the
// stage shades it as it would a line's fragment there, then calls it. vAlpha is the fragment's coverage
// of its pixel times StrandOpacity. A texel past the last fragment is discarded. Every name here begins
// with hairgen, Hairgen or HAIRGEN.
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
uniform int hairgenAtlasRows;        // texels
uniform int hairgenFragmentCount;    // at most the atlas' texels, fewer than 2^31
#define HAIRGEN_POINT(data, i) vec3(data[3 * (i)], data[3 * (i) + 1], data[3 * (i) + 2])
// A fragment's inputs, as hair_vertex.glsl writes them.
struct HairgenInputs {
  vec3 world, tangent, color, normal;
  float alpha, depth;
};
// The inputs of the fragment at the atlas' `texel` (column, row from the bottom); false past the last.
bool hairgenInputs(ivec2 texel, out HairgenInputs v) {
  int at = texel.y * hairgenAtlasWidth + texel.x;
  if (at >= hairgenFragmentCount) return false;
  uint j = uint(at);
  uint i = hairgenFragmentData[3u * j];
  uint word = hairgenFragmentData[3u * j + 2u];
  float coverage = float(word & ((1u << kCoverageBits) - 1u)) / float(kCoverageOne);
  float s = float(word >> kCoverageBits) / float(kSpanUnit);
  v.world = mix(HAIRGEN_POINT(hairgenPointData, i), HAIRGEN_POINT(hairgenPointData, i + 1u), s);
  v.tangent = mix(HAIRGEN_POINT(hairgenTangentData, i), HAIRGEN_POINT(hairgenTangentData, i + 1u), s);
  v.color = hairgenHasColor != 0
                ? mix(HAIRGEN_POINT(hairgenColorData, i), HAIRGEN_POINT(hairgenColorData, i + 1u), s)
                : vec3(1.0);
  v.normal = hairgenHasNormal != 0
                 ? mix(HAIRGEN_POINT(hairgenNormalData, i), HAIRGEN_POINT(hairgenNormalData, i + 1u), s)
                 : vec3(0.0);
  v.alpha = min(coverage * hairgenOpacity, 1.0);
  v.depth = uintBitsToFloat(hairgenFragmentData[3u * j + 1u]);
  return true;
}
#define main hairgenShade
