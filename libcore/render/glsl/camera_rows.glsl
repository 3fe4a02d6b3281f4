// The camera's fragments on the device, between the count and the fill passes: where each row's lists
// and its kept fragments begin among every pixel's (the prefix sums' words at its first pixel; row
// uRows: the totals), for the host to cut the rows into slabs that fit the device's buffers. Totals'
// first word is the deepest pixel's count (the prefix sum's).
layout(local_size_x = 256) in;
layout(std430, binding = 0) readonly buffer Offsets { uint offsetData[]; };  // pixels + 1 words
layout(std430, binding = 1) readonly buffer KeepAt { uint keepAtData[]; };   // pixels + 1 words
layout(std430, binding = 2) writeonly buffer Totals { uint totalData[]; };   // 1 + 2 (uRows + 1) words
uniform uint uWidth, uRows;
void main() {
  uint row = (gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x) * gl_WorkGroupSize.x +
             gl_LocalInvocationID.x;
  if (row > uRows) return;
  totalData[1u + 2u * row] = offsetData[row * uWidth];
  totalData[2u + 2u * row] = keepAtData[row * uWidth];
}
