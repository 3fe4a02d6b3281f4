// Supersampling's coverage for the hair shading fragment stage (hairgen's and a custom HairFrag): with
// k×k sub-pixels per pixel, the sub-pixel of rank j in its block keeps a fragment of opacity `alpha`
// only when alpha > (j + 0.5)/k², so a block's coverage is alpha to within 1/k². Discards the fragment
// otherwise; does nothing without sub-pixels (k = 1), and is empty when SINGLE_SAMPLE says so at
// compile time: a stage with a discard anywhere loses llvmpipe's early depth test, and with it the
// skipping of hidden fragments' shading.
uniform int uBlock;      // k: sub-pixels per pixel side
uniform int uOrder[64];  // the screen door's threshold rank of each sub-pixel of a block, row by row
void screenDoor(float alpha) {
#ifndef SINGLE_SAMPLE
  if (uBlock > 1) {
    ivec2 q = ivec2(gl_FragCoord.xy) % uBlock;
    int j = uOrder[q.y * uBlock + q.x];
    if (alpha <= (float(j) + 0.5) / float(uBlock * uBlock)) discard;
  }
#endif
}
