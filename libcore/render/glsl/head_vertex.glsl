// hairgen's head vertex stage, used by the light's depth pass and the shading pass. The reference for a
// custom HeadVert (README, Custom shaders). MOTION: as in hair_vertex.glsl, for the motion pass only.
layout(location = 0) in vec3 aPosition;  // metres
layout(location = 1) in vec3 aNormal;    // unit; (0, 1, 0) where the mesh has none
uniform mat4 uView;                      // world to view (the camera's or the light's)
uniform mat4 uProj;                      // view to clip
out vec3 vWorld;                         // world position, metres
out vec3 vNormal;
out float vDepth;                        // metres along the view axis
#ifdef MOTION
layout(location = 2) in vec3 aPrevious;  // the vertex in the previous frame
uniform mat4 uViewProj;                  // world to clip, this frame's camera
uniform mat4 uPreviousViewProj;          // world to clip, the previous frame's camera
uniform vec2 uImageSize;                 // the image's pixels
out vec2 vMotion;                        // pixels, x right and y up, since the previous frame
#endif
void main() {
  vec4 view = uView * vec4(aPosition, 1.0);
  gl_Position = uProj * view;
#ifdef MOTION
  vec4 now = uViewProj * vec4(aPosition, 1.0), before = uPreviousViewProj * vec4(aPrevious, 1.0);
  // A point at or behind the camera (w <= 0) in either frame has no place on the image: its w is held
  // just in front, so the move stays finite and the clipped primitive's motion is large, not NaN.
  vMotion = (now.xy / max(now.w, 1e-6) - before.xy / max(before.w, 1e-6)) * 0.5 * uImageSize;
#endif
  vWorld = aPosition;
  vNormal = aNormal;
  vDepth = -view.z;
}
