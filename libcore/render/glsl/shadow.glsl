// The light that reaches a world point, from the light's maps: put in front of the hair and head
// shading fragment stages (hairgen's and custom ones).
//
// Continuous in the point's position: each of the 4 texels around it is evaluated on its own (the
// head's depth compared, the hair's layers read from where the hair begins in that texel), and the 4
// opacities are weighted bilinearly, so the head's shadow edge is a percentage-closer filter and a point
// moving a hundredth of a texel changes its shadow by about a hundredth.
uniform mat4 uLightView;  // world to the light's view
uniform mat4 uLightProj;  // the light's view to clip
layout(binding = kUnitHairStart) uniform sampler2D uStart;
layout(binding = kUnitHeadDepth) uniform sampler2D uHeadDepth;
layout(binding = kUnitOpacityMap) uniform sampler2D uOpacityMap;
uniform vec4 uLayers;     // the deep opacity layers' depths, metres
// The opacity in front of a point `z` metres along the light's axis, through texel `t`: 1 behind the
// head, else the deep opacity layers interpolated in depth from where the hair begins.
float opacityThrough(ivec2 t, float z) {
  if (z > texelFetch(uHeadDepth, t, 0).r + kShadowBiasHeadDepth) return 1.0;  // the head is in the way
  float z0 = texelFetch(uStart, t, 0).r;
  if (z <= z0) return 0.0;
  vec4 op = texelFetch(uOpacityMap, t, 0);
  vec4 ends = z0 + vec4(uLayers.x, uLayers.x + uLayers.y, uLayers.x + uLayers.y + uLayers.z,
                        uLayers.x + uLayers.y + uLayers.z + uLayers.w);
  float s;
  if (z < ends.x) s = mix(0.0, op.r, (z - z0) / uLayers.x);
  else if (z < ends.y) s = mix(op.r, op.g, (z - ends.x) / uLayers.y);
  else if (z < ends.z) s = mix(op.g, op.b, (z - ends.y) / uLayers.z);
  else if (z < ends.w) s = mix(op.b, op.a, (z - ends.z) / uLayers.w);
  else s = op.a;
  return clamp(s, 0.0, 1.0);
}
// `bias`: metres toward the light, so a surface does not shadow itself through the maps' resolution.
// Returns 1 in the open, down to kShadowFloor behind the head or opaque hair.
float lightArriving(vec3 world, float bias) {
  vec4 lv = uLightView * vec4(world, 1.0);
  float z = -lv.z - bias;
  vec4 c = uLightProj * lv;
  vec2 uv = c.xy / c.w * 0.5 + 0.5;
  if (any(lessThan(uv, vec2(0.0))) || any(greaterThan(uv, vec2(1.0)))) return 1.0;
  ivec2 size = textureSize(uStart, 0);
  vec2 texel = uv * vec2(size) - 0.5;
  ivec2 i0 = ivec2(floor(texel));
  vec2 f = texel - vec2(i0);
  ivec2 last = size - 1;
  float o00 = opacityThrough(clamp(i0, ivec2(0), last), z);
  float o10 = opacityThrough(clamp(i0 + ivec2(1, 0), ivec2(0), last), z);
  float o01 = opacityThrough(clamp(i0 + ivec2(0, 1), ivec2(0), last), z);
  float o11 = opacityThrough(clamp(i0 + ivec2(1, 1), ivec2(0), last), z);
  float s = mix(mix(o00, o10, f.x), mix(o01, o11, f.x), f.y);
  return 1.0 - (1.0 - kShadowFloor) * s;
}
