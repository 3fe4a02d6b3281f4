// hairgen's head shading fragment stage: Lambert with the hair's shadows. The reference for a custom
// HeadFrag (README, Custom shaders): its inputs are the head vertex stage's outputs.
in vec3 vWorld;
in vec3 vNormal;
in float vDepth;
uniform vec3 uLightPosition;  // metres
uniform vec3 uLightColor;
uniform float uAmbient;       // AmbientIntensity
uniform vec3 uHeadColor;
layout(location = 0) out vec4 oColor;  // RGB, and 1 (the head is opaque)
layout(location = 1) out vec4 oData;   // Z (metres), hair opacity (0), shadow, 0
void main() {
  vec3 n = normalize(vNormal);
  vec3 l = normalize(uLightPosition - vWorld);
  float shadow = lightArriving(vWorld + kShadowOffsetHead * n, 0.0);
  vec3 color = uAmbient * uHeadColor + shadow * uLightColor * uHeadColor * max(dot(n, l), 0.0);
  oColor = vec4(color, 1.0);
  oData = vec4(vDepth, 0.0, shadow, 0.0);
}
