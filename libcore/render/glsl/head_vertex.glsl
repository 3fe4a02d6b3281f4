// hairgen's head vertex stage, used by the light's depth pass and the shading pass. The reference for a
// custom HeadVert (README, Custom shaders).
layout(location = 0) in vec3 aPosition;  // metres
layout(location = 1) in vec3 aNormal;    // unit; (0, 1, 0) where the mesh has none
uniform mat4 uView;                      // world to view (the camera's or the light's)
uniform mat4 uProj;                      // view to clip
out vec3 vWorld;                         // world position, metres
out vec3 vNormal;
out float vDepth;                        // metres along the view axis
void main() {
  vec4 view = uView * vec4(aPosition, 1.0);
  gl_Position = uProj * view;
  vWorld = aPosition;
  vNormal = aNormal;
  vDepth = -view.z;
}
