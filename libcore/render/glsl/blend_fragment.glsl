// The camera's view blended front to back, per pixel of the shading pass (camera_fragments.h): the kept
// hair fragments nearest first, each as opaque as its shading stage said (its coverage × the strand's
// opacity), the fragments behind them as one layer of their summed coverage, then the head, which is
// opaque. Writes R G B premultiplied and A the share of the pixel's light the hair and head stop; Z the
// nearest drawn; the hair's opacity in front of the head; the shadow (the light arriving) blended as
// the colour is, the open counting 1.
layout(binding = kUnitSubpixelColor) uniform sampler2D uHeadColor;
layout(binding = kUnitSubpixelData) uniform sampler2D uHeadData;
layout(binding = kUnitAtlasColor) uniform sampler2D uAtlasColor;
layout(binding = kUnitAtlasData) uniform sampler2D uAtlasData;
layout(std430, binding = 5) readonly buffer Fragments { uint fragmentData[]; };
layout(std430, binding = 6) readonly buffer PixelFirst { uint pixelFirst[]; };
layout(std430, binding = 7) readonly buffer Tails { uint tailData[]; };
uniform int uAtlasWidth;  // texels
uniform int uImageWidth;  // the shading pass's pixels per row
uniform float uOpacity;   // StrandOpacity
layout(location = 0) out vec4 oColor;
layout(location = 1) out vec4 oData;
void main() {
  ivec2 p = ivec2(gl_FragCoord.xy);
  int pixel = p.y * uImageWidth + p.x;
  vec4 headData = texelFetch(uHeadData, p, 0);
  float headZ = headData.x;  // kBackgroundZ where the head is not
  vec3 color = vec3(0.0);
  float through = 1.0, shadow = 0.0, z = headZ;
  int first = int(pixelFirst[pixel]), end = int(pixelFirst[pixel + 1]);
  vec4 c = vec4(0.0);
  float s = 1.0;
  bool hidden = false;
  for (int j = first; j < end; ++j) {
    float depth = uintBitsToFloat(fragmentData[3 * j + 1]);
    if (depth >= headZ) {  // the rasteriser left none behind the head (the same test); kept as a guard
      hidden = true;
      break;
    }
    ivec2 a = ivec2(j % uAtlasWidth, j / uAtlasWidth);
    c = texelFetch(uAtlasColor, a, 0);
    s = texelFetch(uAtlasData, a, 0).z;
    float alpha = clamp(c.a, 0.0, 1.0);
    color += through * alpha * c.rgb;
    shadow += through * alpha * s;
    through *= 1.0 - alpha;
    z = min(z, depth);
  }
  uint tail = tailData[pixel];
  if (!hidden && tail > 0u && end > first) {
    // Many faint strands let through the product of what each does, exp(−Σ coverage × opacity) for
    // faint ones; lit as the farthest kept fragment.
    float alpha = 1.0 - exp(-float(tail) / float(kCoverageOne) * uOpacity);
    color += through * alpha * c.rgb;
    shadow += through * alpha * s;
    through *= 1.0 - alpha;
  }
  float hair = 1.0 - through;
  if (headZ < kBackgroundZ) {
    color += through * texelFetch(uHeadColor, p, 0).rgb;
    shadow += through * headData.z;
    through = 0.0;
  }
  shadow += through;
  oColor = vec4(color, 1.0 - through);
  oData = vec4(z, hair, shadow, 0.0);
}
