// Box-filters each k×k block of sub-pixels: color, A, hair opacity and shadow averaged, Z the nearest.
// A sub-pixel's A is what the shading pass blended (uBlended), or, where it drew opaque samples, 1 where
// something was drawn (its Z nearer than kBackgroundZ); either way R G B A are premultiplied:
// R G B + (1 − A) × background is the picture over a background.
layout(binding = kUnitSubpixelColor) uniform sampler2D uColor;
layout(binding = kUnitSubpixelData) uniform sampler2D uData;
uniform int uBlock;    // k: sub-pixels per pixel side
uniform int uBlended;  // 1: the sub-pixels' A is their blended opacity; 0: their samples are opaque
layout(location = 0) out vec4 oColor;
layout(location = 1) out vec4 oData;
void main() {
  ivec2 p = ivec2(gl_FragCoord.xy) * uBlock;
  vec3 color = vec3(0.0);
  float z = 3.0e38, covered = 0.0, opacity = 0.0, shadow = 0.0;
  for (int y = 0; y < uBlock; ++y)
    for (int x = 0; x < uBlock; ++x) {
      vec4 c = texelFetch(uColor, p + ivec2(x, y), 0);
      vec4 data = texelFetch(uData, p + ivec2(x, y), 0);
      color += c.rgb;
      z = min(z, data.x);
      covered += uBlended != 0 ? c.a : (data.x < kBackgroundZ ? 1.0 : 0.0);
      opacity += data.y;
      shadow += data.z;
    }
  float n = float(uBlock * uBlock);
  oColor = vec4(color / n, covered / n);
  oData = vec4(z, opacity / n, shadow / n, 0.0);
}
