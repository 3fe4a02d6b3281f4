// Exclusive prefix sums on the device (compute_raster.h: PrefixSum), work-efficient as Blelloch's scan
// (G. E. Blelloch, "Prefix sums and their applications", 1990: an up-sweep that sums a balanced tree in
// place, then a down-sweep that hands each node the sum of everything to its left). Unsigned sums, modulo 2^32:
// integer addition is associative, so the bits do not depend on the order the device adds in.
// SCAN_BLOCKS: each group of kScanLanes invocations scans a block of kScanBlock words
// (kScanPerInvocation in turn per invocation, then the invocations' totals in shared memory), and
// writes the block's total; ADD_BLOCKS: each word gets its block's place among the blocks (the blocks'
// totals, scanned). The host defines SCAN_LANES and SCAN_PER_INVOCATION (compute_raster.h: PrefixSum).
// An invocation loops 2 log2(kScanLanes) + 2 kScanPerInvocation times: far inside a software
// rasteriser's loop budget.
const uint kScanLanes = uint(SCAN_LANES), kScanPerInvocation = uint(SCAN_PER_INVOCATION);
const uint kScanBlock = kScanLanes * kScanPerInvocation;
uniform uint uSums;  // the sums written: words [0, uSums) of Out

#ifdef SCAN_BLOCKS
layout(local_size_x = SCAN_LANES) in;
layout(std430, binding = 0) readonly buffer In { uint inData[]; };
layout(std430, binding = 1) writeonly buffer Out { uint outData[]; };
layout(std430, binding = 2) writeonly buffer BlockSums { uint blockSumData[]; };
layout(std430, binding = 3) buffer Deepest { uint deepestData[]; };
uniform uint uInputs;  // words of In; those past them count 0
uniform uint uLimit;   // each word counts at most this much
uniform int uDeepest;  // 1: the largest word of In raises Deepest's first
shared uint partial[kScanLanes];
shared uint groupDeepest;

void main() {
  // Barriers only in uniform control flow: a group past the end (dispatch's rows of groups) runs
  // through them too, reading and writing nothing.
  uint block = gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x;
  bool inside = block * kScanBlock < uSums;
  uint lane = gl_LocalInvocationID.x, first = block * kScanBlock + lane * kScanPerInvocation;
  uint before[kScanPerInvocation];
  uint sum = 0u, deepest = 0u;
  for (uint k = 0u; k < kScanPerInvocation; ++k) {
    uint word = first + k < uInputs ? inData[first + k] : 0u;
    deepest = max(deepest, word);
    before[k] = sum;
    sum += min(word, uLimit);
  }
  partial[lane] = sum;
  if (lane == 0u) groupDeepest = 0u;
  for (uint d = 1u; d < kScanLanes; d <<= 1) {
    barrier();
    uint at = (lane + 1u) * 2u * d - 1u;
    if (at < kScanLanes) partial[at] += partial[at - d];
  }
  barrier();
  if (lane == 0u) {
    if (inside) blockSumData[block] = partial[kScanLanes - 1u];
    partial[kScanLanes - 1u] = 0u;
  }
  for (uint d = kScanLanes / 2u; d > 0u; d >>= 1) {
    barrier();
    uint at = (lane + 1u) * 2u * d - 1u;
    if (at < kScanLanes) {
      uint left = partial[at - d];
      partial[at - d] = partial[at];
      partial[at] += left;
    }
  }
  barrier();
  for (uint k = 0u; k < kScanPerInvocation; ++k)
    if (first + k < uSums) outData[first + k] = partial[lane] + before[k];
  if (uDeepest != 0) atomicMax(groupDeepest, deepest);  // uniform: every invocation or none
  barrier();
  if (lane == 0u && uDeepest != 0) atomicMax(deepestData[0], groupDeepest);
}
#endif

#ifdef ADD_BLOCKS
layout(local_size_x = 256) in;
layout(std430, binding = 1) buffer Out { uint outData[]; };
layout(std430, binding = 2) readonly buffer BlockSums { uint blockSumData[]; };  // scanned
void main() {
  uint i = (gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x) * gl_WorkGroupSize.x +
           gl_LocalInvocationID.x;
  if (i < uSums) outData[i] += blockSumData[i / kScanBlock];
}
#endif
