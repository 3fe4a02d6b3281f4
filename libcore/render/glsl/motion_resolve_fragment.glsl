// Averages the motion of each k×k block's covered sub-pixels (0 where none is covered): motion vectors
// are not premultiplied, so an edge pixel moves as what covers it does.
layout(binding = kUnitSubpixelMotion) uniform sampler2D uMotion;
uniform int uBlock;  // k: sub-pixels per pixel side
layout(location = 0) out vec4 oMotion;
void main() {
  ivec2 p = ivec2(gl_FragCoord.xy) * uBlock;
  vec2 motion = vec2(0.0);
  float covered = 0.0;
  for (int y = 0; y < uBlock; ++y)
    for (int x = 0; x < uBlock; ++x) {
      vec4 m = texelFetch(uMotion, p + ivec2(x, y), 0);
      motion += m.xy * m.z;
      covered += m.z;
    }
  oMotion = vec4(covered > 0.0 ? motion / covered : vec2(0.0), 0.0, 0.0);
}
