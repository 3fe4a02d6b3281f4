// Box-filters each k×k block of sub-pixels: color, hair opacity and shadow averaged, Z the nearest.
layout(binding = kUnitSubpixelColor) uniform sampler2D uColor;
layout(binding = kUnitSubpixelData) uniform sampler2D uData;
uniform int uBlock;  // k: sub-pixels per pixel side
layout(location = 0) out vec4 oColor;
layout(location = 1) out vec4 oData;
void main() {
  ivec2 p = ivec2(gl_FragCoord.xy) * uBlock;
  vec4 color = vec4(0.0);
  float z = 3.0e38, opacity = 0.0, shadow = 0.0;
  for (int y = 0; y < uBlock; ++y)
    for (int x = 0; x < uBlock; ++x) {
      color += texelFetch(uColor, p + ivec2(x, y), 0);
      vec4 data = texelFetch(uData, p + ivec2(x, y), 0);
      z = min(z, data.x);
      opacity += data.y;
      shadow += data.z;
    }
  float n = float(uBlock * uBlock);
  oColor = color / n;
  oData = vec4(z, opacity / n, shadow / n, 0.0);
}
