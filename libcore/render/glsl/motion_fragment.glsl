// The motion pass's fragment stage, for the hair (with the shading pass's screen door, SCREEN_DOOR defined, so the
// same strand wins each sub-pixel) and for the head: the screen motion since the previous frame, and 1
// where something was drawn.
in vec2 vMotion;
#ifdef SCREEN_DOOR
in float vAlpha;
#endif
layout(location = 0) out vec4 oMotion;  // u, v (pixels), covered, 0
void main() {
#ifdef SCREEN_DOOR
  screenDoor(vAlpha);
#endif
  oMotion = vec4(vMotion, 1.0, 0.0);
}
