// The light that reaches a world point, from the light's maps: put in front of the hair and head
// shading fragment stages (hairgen's and custom ones).
uniform mat4 uLightView;  // world to the light's view
uniform mat4 uLightProj;  // the light's view to clip
layout(binding = kUnitHairStart) uniform sampler2D uStart;
layout(binding = kUnitHeadDepth) uniform sampler2D uHeadDepth;
layout(binding = kUnitOpacityMap) uniform sampler2D uOpacityMap;
uniform vec4 uLayers;     // the deep opacity layers' depths, metres
// `bias`: metres toward the light, so a surface does not shadow itself through the maps' resolution.
// Returns 1 in the open, down to kShadowFloor behind the head or opaque hair.
float lightArriving(vec3 world, float bias) {
  vec4 lv = uLightView * vec4(world, 1.0);
  float z = -lv.z - bias;
  vec4 c = uLightProj * lv;
  vec2 uv = c.xy / c.w * 0.5 + 0.5;
  if (any(lessThan(uv, vec2(0.0))) || any(greaterThan(uv, vec2(1.0)))) return 1.0;
  if (z > texture(uHeadDepth, uv).r + kShadowBiasHeadDepth) return kShadowFloor;  // the head is in the way: opaque
  // Over the 2×2 texels around the point: where the hair begins nearest, and each layer's largest
  // opacity, so a strand one texel wide still shadows what lies behind it.
  vec4 starts = textureGather(uStart, uv, 0);
  float z0 = min(min(starts.x, starts.y), min(starts.z, starts.w));
  vec4 g0 = textureGather(uOpacityMap, uv, 0), g1 = textureGather(uOpacityMap, uv, 1);
  vec4 g2 = textureGather(uOpacityMap, uv, 2), g3 = textureGather(uOpacityMap, uv, 3);
  vec4 op = vec4(max(max(g0.x, g0.y), max(g0.z, g0.w)), max(max(g1.x, g1.y), max(g1.z, g1.w)),
                 max(max(g2.x, g2.y), max(g2.z, g2.w)), max(max(g3.x, g3.y), max(g3.z, g3.w)));
  vec4 ends = z0 + vec4(uLayers.x, uLayers.x + uLayers.y, uLayers.x + uLayers.y + uLayers.z,
                        uLayers.x + uLayers.y + uLayers.z + uLayers.w);
  float s;
  if (z <= z0) s = 0.0;
  else if (z < ends.x) s = mix(0.0, op.r, (z - z0) / uLayers.x);
  else if (z < ends.y) s = mix(op.r, op.g, (z - ends.x) / uLayers.y);
  else if (z < ends.z) s = mix(op.g, op.b, (z - ends.y) / uLayers.z);
  else if (z < ends.w) s = mix(op.b, op.a, (z - ends.z) / uLayers.w);
  else s = op.a;
  return 1.0 - (1.0 - kShadowFloor) * clamp(s, 0.0, 1.0);
}
