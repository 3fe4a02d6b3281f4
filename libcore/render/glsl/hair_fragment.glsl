// hairgen's hair shading fragment stage (thesis §4.1.5, the formulas of libcore/render/shading.h). The
// reference for a custom HairFrag (README, Custom shaders): its inputs are the hair vertex stage's
// outputs, and it writes the color and the data the resolve pass averages.
in vec3 vWorld;
in vec3 vTangent;
in vec3 vColor;
in vec3 vNormal;
in float vAlpha;
in float vDepth;
uniform vec3 uEye;            // the camera's position, metres
uniform vec3 uLightPosition;  // metres
uniform vec3 uLightColor;
uniform float uAmbient;       // AmbientIntensity
uniform vec3 uAmbientColor;
uniform vec3 uDiffuseColor;
uniform vec3 uSpecularColor;
uniform float uGlossiness;
uniform int uModel;           // ShadingModel: kShadingKajiyaKay, kShadingThesis, kShadingAnjyo, ...
// hairgen's own stage is compiled for the render's model (HAIR_MODEL) and, when the hair has no colours,
// with white in place of vColor (HAIR_WHITE), so the vertex stage's unused outputs are dropped at link.
#ifndef HAIR_MODEL
#define HAIR_MODEL uModel
#endif
#ifdef HAIR_WHITE
#define HAIR_COLOR vec3(1.0)
#else
#define HAIR_COLOR vColor
#endif
uniform float uBlend;         // volumetric: its share against Kajiya-Kay
layout(location = 0) out vec4 oColor;  // RGB, and the strand's opacity
layout(location = 1) out vec4 oData;   // Z (metres), hair opacity (1), shadow, 0
void main() {
  screenDoor(vAlpha);
  vec3 t = normalize(vTangent);
  vec3 l = normalize(uLightPosition - vWorld);
  vec3 e = normalize(uEye - vWorld);
  float tl = dot(t, l), te = dot(t, e);
  float sinTL = sqrt(max(0.0, 1.0 - tl * tl)), sinTE = sqrt(max(0.0, 1.0 - te * te));
  float diffuse = sinTL, specular;
  if (HAIR_MODEL == kShadingAnjyo) {
    float th = dot(t, normalize(l + e));
    specular = pow(max(1.0 - th * th, 0.0), 0.5 * uGlossiness);
    diffuse = 0.0;
  } else {
    float cone = HAIR_MODEL == kShadingThesis ? abs(tl) * abs(te) + sinTL * sinTE : -tl * te + sinTL * sinTE;
    specular = pow(max(cone, 0.0), uGlossiness);
  }
  float shadow = lightArriving(vWorld, kShadowBiasHair);
  vec3 color = uAmbient * uAmbientColor * HAIR_COLOR +
               shadow * uLightColor * (uDiffuseColor * HAIR_COLOR * diffuse + uSpecularColor * specular);
  if (HAIR_MODEL == kShadingVolumetric) {
    // The strand as a point of the hair's surface, lit about the volume normal.
    vec3 n = dot(vNormal, vNormal) > 0.0 ? normalize(vNormal) : vec3(0.0);
    float surfaceDiffuse = max(dot(n, l), 0.0);
    float phong = pow(max(dot(reflect(-l, n), e), 0.0), uGlossiness);
    vec3 volumetric = uAmbient * uAmbientColor * HAIR_COLOR +
                      shadow * uLightColor * (uDiffuseColor * HAIR_COLOR * surfaceDiffuse + uSpecularColor * phong);
    color = mix(color, volumetric, uBlend);
  }
  oColor = vec4(color, vAlpha);
  oData = vec4(vDepth, 1.0, shadow, 0.0);
}
