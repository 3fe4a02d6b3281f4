// The camera's fragments on the device, third pass, per pixel: its list sorted by segment (the order the
// CPU's bands draw them in), then kept as camera_fragments.cpp keeps them: the KEPT nearest, one
// strand's consecutive pieces merged, the rest's coverage in the tail. For the pixels [uPixelLo,
// uPixelHi) of a slab. The kept fragments' three words go to the pixel's place in Staging (the prefix
// sum of min(count, KEPT)), their count to Kept. A list the fill pass did not fill exactly (the two
// passes disagreed on a pixel's fragments) is reported, and the host draws the frame's fragments on the CPU.
layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Offsets { uint offsetData[]; };  // among every pixel's
layout(std430, binding = 1) readonly buffer Counts { uint countData[]; };
layout(std430, binding = 2) buffer Lists { uvec4 listData[]; };
layout(std430, binding = 3) buffer Kept { uint keptData[]; };
layout(std430, binding = 4) writeonly buffer Tails { uint tailData[]; };
layout(std430, binding = 5) readonly buffer KeepAt { uint keepAtData[]; };
layout(std430, binding = 6) writeonly buffer Staging { uint stagingData[]; };
layout(std430, binding = 7) readonly buffer Cursors { uint cursorData[]; };
uniform uint uPixelLo, uPixelHi;
uniform uint uSlabFirst;  // the slab's first pixel's offset
uniform uint uFault;  // where in Kept a pixel whose list the fill pass did not fill exactly sets 1
uniform double uDepthUnit;
// The kept fragments, nearest first, a field an array (arrays of structures indexed at run time were
// miscompiled by llvmpipe): depth (kDepthUnit, the nearest piece's), origin (the first piece's segment,
// which orders equal depths), point (the segment of the largest piece, shaded), last (the last segment
// merged), coverage (all pieces'), largest (the largest piece's coverage), span (where that piece lies).
int slotDepth[KEPT + 1];
uint slotOrigin[KEPT + 1], slotPoint[KEPT + 1], slotLast[KEPT + 1], slotCoverage[KEPT + 1], slotLargest[KEPT + 1],
    slotSpan[KEPT + 1];  // one spare, for swaps
bool nearer(int depthA, uint originA, int k) {
  return depthA != slotDepth[k] ? depthA < slotDepth[k] : originA < slotOrigin[k];
}
void move(int to, int from) {
  slotDepth[to] = slotDepth[from];
  slotOrigin[to] = slotOrigin[from];
  slotPoint[to] = slotPoint[from];
  slotLast[to] = slotLast[from];
  slotCoverage[to] = slotCoverage[from];
  slotLargest[to] = slotLargest[from];
  slotSpan[to] = slotSpan[from];
}
void put(int k, int depth, uint origin, uint point, uint last, uint coverage, uint largest, uint span) {
  slotDepth[k] = depth;
  slotOrigin[k] = origin;
  slotPoint[k] = point;
  slotLast[k] = last;
  slotCoverage[k] = coverage;
  slotLargest[k] = largest;
  slotSpan[k] = span;
}
uint addSaturating(uint sum, uint add) {
  return add > 0xFFFFFFFFu - sum ? 0xFFFFFFFFu : sum + add;
}
// Moves the list's entry at `root` down its heap [0, end) (by segment, largest on top).
void siftDown(uint base, uint root, uint end) {
  while (2u * root + 1u < end) {
    uint child = 2u * root + 1u;
    if (child + 1u < end && listData[base + child].x < listData[base + child + 1u].x) ++child;
    uvec4 top = listData[base + root], below = listData[base + child];
    if (top.x >= below.x) return;
    listData[base + root] = below;
    listData[base + child] = top;
    root = child;
  }
}

// The pixel's list in the order of its segments (each segment leaves a pixel one fragment, so the keys
// are distinct and any sort gives the same list): by insertion when short, a heap sort when long.
void sortBySegment(uint base, uint n) {
  if (n <= 32u) {
    for (uint i = 1u; i < n; ++i) {
      uvec4 f = listData[base + i];
      uint j = i;
      while (j > 0u) {
        uvec4 g = listData[base + j - 1u];
        if (g.x <= f.x) break;
        listData[base + j] = g;
        --j;
      }
      listData[base + j] = f;
    }
    return;
  }
  for (uint start = n / 2u; start > 0u; --start) siftDown(base, start - 1u, n);
  for (uint end = n - 1u; end > 0u; --end) {
    uvec4 top = listData[base];
    listData[base] = listData[base + end];
    listData[base + end] = top;
    siftDown(base, 0u, end);
  }
}

void main() {
  uint p = uPixelLo + (gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x) * gl_WorkGroupSize.x +
           gl_LocalInvocationID.x;
  if (p >= uPixelHi) return;
  uint base = offsetData[p] - uSlabFirst, n = countData[p];
  if (cursorData[p] != n) {
    keptData[uFault] = 1u;
    return;
  }
  sortBySegment(base, n);
  int used = 0;
  uint tail = 0u;
  for (uint i = 0u; i < n; ++i) {
    uvec4 f = listData[base + i];
    int depth = int(f.y);
    uint point = f.x, coverage = f.z;
    // A piece of the same strand from the same segment or the one before merges into its fragment.
    int merged = -1;
    for (int k = 0; k < used && merged < 0; ++k)
      if (point - slotLast[k] <= 1u) merged = k;
    if (merged >= 0) {
      int k = merged;
      slotCoverage[k] = addSaturating(slotCoverage[k], coverage);
      slotLast[k] = point;
      if (coverage > slotLargest[k]) {
        slotLargest[k] = coverage;
        slotPoint[k] = point;
        slotSpan[k] = f.w;
      }
      if (depth < slotDepth[k]) {
        slotDepth[k] = depth;
        for (int j = k; j > 0; --j) {
          if (!nearer(slotDepth[j], slotOrigin[j], j - 1)) break;
          move(KEPT, j);
          move(j, j - 1);
          move(j - 1, KEPT);
        }
      }
      continue;
    }
    if (used == KEPT) {
      if (!nearer(depth, point, used - 1)) {
        tail = addSaturating(tail, coverage);
        continue;
      }
      tail = addSaturating(tail, slotCoverage[--used]);
    }
    int j = used++;
    while (j > 0) {
      if (!nearer(depth, point, j - 1)) break;
      move(j, j - 1);
      --j;
    }
    put(j, depth, point, point, point, coverage, coverage, f.w);
  }
  uint at = 3u * keepAtData[p];
  for (int k = 0; k < used; ++k) {
    stagingData[at + 3u * uint(k)] = slotPoint[k];
    stagingData[at + 3u * uint(k) + 1u] = floatBitsToUint(float(double(slotDepth[k]) * uDepthUnit));
    stagingData[at + 3u * uint(k) + 2u] = min(slotCoverage[k], kCoverageOne) | (slotSpan[k] << kCoverageBits);
  }
  keptData[p] = uint(used);
  tailData[p] = tail;
}
