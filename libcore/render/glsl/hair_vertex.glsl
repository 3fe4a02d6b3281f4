// hairgen's hair vertex stage, used by every pass that draws hair: the light's depth and deep opacity
// passes (lines) and the shading pass (lines, or ribbons when RIBBON is defined). The reference for a
// custom HairVert (README, Custom shaders).
//
// Lines: one vertex per point, the point's data as vertex attributes. Ribbons: two vertices per point
// (gl_VertexID 2i and 2i + 1 for point i), the data read from storage buffers, the pair pushed apart
// across the strand on screen.
//
// MOTION is defined only in hairgen's motion pass (render --motion), never for a custom HairVert: the
// point's position in the previous frame (attribute 4, storage buffer 4) is projected by that frame's
// camera, and vMotion is how far the point moved on the image since, in pixels.
#ifdef RIBBON
layout(std430, binding = 0) readonly buffer Points { float pointData[]; };
layout(std430, binding = 1) readonly buffer Tangents { float tangentData[]; };
layout(std430, binding = 2) readonly buffer Colors { float colorData[]; };
layout(std430, binding = 3) readonly buffer Normals { float normalData[]; };
uniform int uHasColor;
uniform int uHasNormal;
#ifdef MOTION
layout(std430, binding = 4) readonly buffer PreviousPoints { float previousData[]; };
#endif
#else
layout(location = 0) in vec3 aPosition;
layout(location = 1) in vec3 aTangent;
layout(location = 2) in vec3 aColor;   // (1, 1, 1) when the cache has no colors
layout(location = 3) in vec3 aNormal;  // (0, 0, 0) when the cache has no normals
#ifdef MOTION
layout(location = 4) in vec3 aPrevious;  // the point in the previous frame
#endif
#endif
#ifdef MOTION
uniform mat4 uViewProj;          // world to clip, this frame's camera (as uPreviousViewProj is made)
uniform mat4 uPreviousViewProj;  // world to clip, the previous frame's camera
uniform vec2 uImageSize;         // the image's pixels (not the sub-pixels')
out vec2 vMotion;                // pixels, x right and y up, since the previous frame
#endif
uniform mat4 uView;       // world to view (the camera's or the light's)
uniform mat4 uProj;       // view to clip
uniform vec2 uViewport;   // pixels
uniform float uFocalPx;   // pixels per metre at one metre of depth
uniform float uWidth;     // strand diameter, metres
uniform float uOpacity;
uniform float uMinWidth;  // pixels: the narrowest ribbon
out vec3 vWorld;          // world position, metres
out vec3 vTangent;        // world tangent (not normalised)
out vec3 vColor;          // the strand's per-vertex color, (1, 1, 1) when it has none
out vec3 vNormal;         // the stored volume normal, (0, 0, 0) when there is none
out float vAlpha;         // the strand's opacity
out float vDepth;         // metres along the view axis
void main() {
#ifdef RIBBON
  int i = gl_VertexID >> 1;
  vec3 p = vec3(pointData[3 * i], pointData[3 * i + 1], pointData[3 * i + 2]);
#ifdef MOTION
  vec3 previous = vec3(previousData[3 * i], previousData[3 * i + 1], previousData[3 * i + 2]);
#endif
  vec3 t = vec3(tangentData[3 * i], tangentData[3 * i + 1], tangentData[3 * i + 2]);
  vColor = uHasColor != 0 ? vec3(colorData[3 * i], colorData[3 * i + 1], colorData[3 * i + 2]) : vec3(1.0);
  vNormal = uHasNormal != 0 ? vec3(normalData[3 * i], normalData[3 * i + 1], normalData[3 * i + 2]) : vec3(0.0);
#else
  vec3 p = aPosition;
#ifdef MOTION
  vec3 previous = aPrevious;
#endif
  vec3 t = aTangent;
  vColor = aColor;
  vNormal = aNormal;
#endif
  vec4 view = uView * vec4(p, 1.0);
  vec4 clip = uProj * view;
  float depth = -view.z;
#ifdef MOTION
  // Both ends the same way, so what did not move moved by exactly 0.
  vec4 now = uViewProj * vec4(p, 1.0), before = uPreviousViewProj * vec4(previous, 1.0);
  // A point at or behind the camera (w <= 0) in either frame has no place on the image: its w is held
  // just in front, so the move stays finite and the clipped primitive's motion is large, not NaN.
  vMotion = (now.xy / max(now.w, 1e-6) - before.xy / max(before.w, 1e-6)) * 0.5 * uImageSize;
#endif
#ifdef RIBBON
  float side = (gl_VertexID & 1) == 0 ? -1.0 : 1.0;
  vec4 ahead = uProj * (view + uView * vec4(1e-3 * t, 0.0));
  vec2 d = (ahead.xy / ahead.w - clip.xy / clip.w) * uViewport;
  float len = length(d);
  vec2 across = len > 1e-9 ? vec2(-d.y, d.x) / len : vec2(1.0, 0.0);
  float widthPx = uWidth * uFocalPx / max(depth, 1e-6);
  clip.xy += across * (side * 0.5 * max(widthPx, uMinWidth)) * 2.0 / uViewport * clip.w;
#endif
  gl_Position = clip;
  vWorld = p;
  vTangent = t;
  vAlpha = uOpacity;
  vDepth = depth;
}
