#include "libcore/volume/splat.h"

#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "libcore/util/vectorise.h"

namespace hairgen {

namespace {

constexpr double kSplatOne = 4294967296.0;  // 2^32: splat's weights are 32.32 fixed point
constexpr size_t kSplatBlock = 256;

// One corner's 32.32 weight for a block of points: int64(w·2^32 + 0.5), w the product of the tent
// weights in x, y, z in that order. x = w·2^32 + 0.5 lies in [0.5, 2^33), where adding 2^52 rounds it
// to the nearest integer exactly and leaves that integer in the low bits; one less where that rounded
// up is the truncation int64(x) takes. All of it runs in vector registers, which a double-to-int64
// conversion does not before AVX-512.
template <int dx, int dy, int dz>
inline __attribute__((always_inline)) void cornerWeights(size_t count, const double* __restrict fx,
                                                         const double* __restrict fy,
                                                         const double* __restrict fz, int64_t* __restrict w) {
  HAIRGEN_IVDEP
  for (size_t p = 0; p < count; ++p) {
    const double x =
        (dx ? fx[p] : 1 - fx[p]) * (dy ? fy[p] : 1 - fy[p]) * (dz ? fz[p] : 1 - fz[p]) * kSplatOne + 0.5;
    const double y = x + 0x1p52;
    w[p] = std::bit_cast<int64_t>(y) - std::bit_cast<int64_t>(0x1p52) - (y - 0x1p52 > x ? 1 : 0);
  }
}

// The cells (floor of the grid coordinate) and the eight corner weights of a block of points.
HAIRGEN_VECTOR_CLONES
void splatBlock(const glm::dvec3& origin, double voxel, const glm::vec3* __restrict points, size_t count,
                int* __restrict cell, int64_t* __restrict w) {
  constexpr size_t kB = kSplatBlock;
  double f[3 * kB];
  const float* const xyz = &points[0].x;
  for (int axis = 0; axis < 3; ++axis) {
    const double o = axis == 0 ? origin.x : axis == 1 ? origin.y : origin.z;
    HAIRGEN_IVDEP
    for (size_t p = 0; p < count; ++p) {
      const double g = (double(xyz[3 * p + axis]) - o) / voxel;
      const int truncated = static_cast<int>(g);
      const int c = double(truncated) > g ? truncated - 1 : truncated;  // floor(g), in vector registers
      cell[axis * kB + p] = c;
      f[axis * kB + p] = g - double(c);
    }
  }
  const double *fx = f, *fy = f + kB, *fz = f + 2 * kB;
  cornerWeights<0, 0, 0>(count, fx, fy, fz, w);
  cornerWeights<1, 0, 0>(count, fx, fy, fz, w + kB);
  cornerWeights<0, 1, 0>(count, fx, fy, fz, w + 2 * kB);
  cornerWeights<1, 1, 0>(count, fx, fy, fz, w + 3 * kB);
  cornerWeights<0, 0, 1>(count, fx, fy, fz, w + 4 * kB);
  cornerWeights<1, 0, 1>(count, fx, fy, fz, w + 5 * kB);
  cornerWeights<0, 1, 1>(count, fx, fy, fz, w + 6 * kB);
  cornerWeights<1, 1, 1>(count, fx, fy, fz, w + 7 * kB);
}

}  // namespace

void splat(Grid& d, std::span<const glm::vec3> points) {
  // Weights are added as 32.32 fixed-point integers: integer sums do not depend on the order of the
  // additions, so however the points fall to threads the grid is the same bits on every run and thread
  // count. Each point's eight weights are rounded to sum to exactly one (the rounding is given to its
  // largest weight), so a point inside the grid adds exactly 1 to it.
  // Each thread sums into a grid of its own (atomic adds to one shared grid cost more than the rest of
  // the splat together); the threads' grids are added node by node after, which integer sums allow.
  constexpr size_t kB = kSplatBlock;
  tbb::enumerable_thread_specific<std::vector<int64_t>> partial(
      [&] { return std::vector<int64_t>(d.values.size(), 0); });
  const glm::ivec3 size = d.size;
  const size_t strideY = size_t(size.x), strideZ = strideY * size_t(size.y);
  const size_t copies = std::clamp<size_t>(size_t(kSplatCopiesBytes / (8.0 * double(d.values.size()) + 1.0)),
                                           1, size_t(tbb::this_task_arena::max_concurrency()));
  tbb::task_arena(int(copies)).execute([&] {
    tbb::parallel_for(
        tbb::blocked_range<size_t>(0, points.size(), 4096), [&](const tbb::blocked_range<size_t>& r) {
          std::vector<int64_t>& sums = partial.local();
          int cell[3 * kB];
          int64_t weights[8 * kB];
          for (size_t first = r.begin(); first < r.end(); first += kB) {
            const size_t count = std::min(kB, r.end() - first);
            splatBlock(d.origin, d.voxel, &points[first], count, cell, weights);
            for (size_t p = 0; p < count; ++p) {
              int64_t w[8];
              int64_t total = 0;
              int largest = 0;
              for (int corner = 0; corner < 8; ++corner) {
                w[corner] = weights[corner * kB + p];
                total += w[corner];
                if (w[corner] > w[largest]) largest = corner;
              }
              w[largest] += int64_t(kSplatOne) - total;
              const glm::ivec3 c(cell[p], cell[kB + p], cell[2 * kB + p]);
              if (glm::all(glm::greaterThanEqual(c, glm::ivec3(0))) && glm::all(glm::lessThan(c + 1, size))) {
                const size_t base = d.index(c.x, c.y, c.z);
                sums[base] += w[0];
                sums[base + 1] += w[1];
                sums[base + strideY] += w[2];
                sums[base + strideY + 1] += w[3];
                sums[base + strideZ] += w[4];
                sums[base + strideZ + 1] += w[5];
                sums[base + strideZ + strideY] += w[6];
                sums[base + strideZ + strideY + 1] += w[7];
                continue;
              }
              for (int corner = 0; corner < 8; ++corner) {  // on the grid's edge, the outer corners fall away
                const glm::ivec3 n = c + glm::ivec3(corner & 1, (corner >> 1) & 1, corner >> 2);
                if (glm::any(glm::lessThan(n, glm::ivec3(0))) || glm::any(glm::greaterThanEqual(n, size)))
                  continue;
                sums[d.index(n.x, n.y, n.z)] += w[corner];
              }
            }
          }
        });
  });
  tbb::parallel_for(tbb::blocked_range<size_t>(0, d.values.size(), 16384),
                    [&](const tbb::blocked_range<size_t>& r) {
                      for (size_t i = r.begin(); i != r.end(); ++i) {
                        int64_t sum = 0;
                        for (const std::vector<int64_t>& sums : partial) sum += sums[i];
                        d.values[i] += static_cast<float>(double(sum) / kSplatOne);
                      }
                    });
}

template <class T>
void splatValues(GridOf<T>& d, const std::vector<glm::dvec3>& points, const std::vector<T>& values,
                 SplatEntries<T>& sorted) {
  // Slab s holds the points whose cell starts at node plane z = s − 1 (z = −1 for a point just below
  // the grid): they add to planes z and z + 1 only, so slabs two apart never share a node and each
  // phase (even slabs, then odd) may run its slabs at once. A counting sort keeps each slab's points in
  // index order, so every node sums the same terms in the same order on any thread count.
  const int slabs = d.size.z + 1;
  constexpr uint32_t kOutside = ~0u;
  std::vector<uint32_t> slabOf(points.size());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, points.size(), 8192),
                    [&](const tbb::blocked_range<size_t>& r) {
                      for (size_t p = r.begin(); p != r.end(); ++p) {
                        const double z = std::floor((points[p].z - d.origin.z) / d.voxel) + 1.0;
                        slabOf[p] = z >= 0.0 && z < double(slabs) ? uint32_t(z) : kOutside;
                      }
                    });
  // The points and values themselves, sorted: the splat then reads them in order (through an index it
  // missed the cache on most points, a third of its time). The counting sort runs on fixed chunks of the
  // points at once: chunk c's points of slab s go after every earlier chunk's, so the order is the
  // serial sort's (by slab, then by index) on any thread count.
  constexpr size_t kChunk = 32768;
  const size_t chunks = (points.size() + kChunk - 1) / kChunk, stride = size_t(slabs) + 1;
  std::vector<uint32_t> counts(chunks * stride, 0);  // per chunk, per slab s at s + 1
  tbb::parallel_for(size_t(0), chunks, [&](size_t c) {
    uint32_t* count = &counts[c * stride];
    for (size_t p = c * kChunk; p < std::min(points.size(), (c + 1) * kChunk); ++p)
      if (slabOf[p] != kOutside) ++count[slabOf[p] + 1];
  });
  std::vector<uint32_t> first(stride, 0);
  for (size_t s = 0; s + 1 < stride; ++s) {
    uint32_t at = first[s];
    for (size_t c = 0; c < chunks; ++c) {  // counts becomes each chunk's first place in slab s
      const uint32_t n = counts[c * stride + s + 1];
      counts[c * stride + s + 1] = at;
      at += n;
    }
    first[s + 1] = at;
  }
  sorted.resize(first[size_t(slabs)]);
  tbb::parallel_for(size_t(0), chunks, [&](size_t c) {
    uint32_t* next = &counts[c * stride + 1];
    for (size_t p = c * kChunk; p < std::min(points.size(), (c + 1) * kChunk); ++p)
      if (slabOf[p] != kOutside) sorted[next[slabOf[p]]++] = {points[p], values[p]};
  });
  const glm::ivec3 size = d.size;
  for (int phase = 0; phase < 2; ++phase) {
    tbb::parallel_for(0, (slabs - phase + 1) / 2, [&](int half) {
      const int s = 2 * half + phase;
      for (uint32_t o = first[s]; o < first[s + 1]; ++o) {
        const auto& [point, value] = sorted[o];
        const glm::dvec3 g = (point - d.origin) / d.voxel;
        const glm::ivec3 c = glm::ivec3(glm::floor(g));
        const glm::dvec3 f = g - glm::dvec3(c);
        for (int dz = 0; dz < 2; ++dz)
          for (int dy = 0; dy < 2; ++dy)
            for (int dx = 0; dx < 2; ++dx) {
              const glm::ivec3 n = c + glm::ivec3(dx, dy, dz);
              if (glm::any(glm::lessThan(n, glm::ivec3(0))) || glm::any(glm::greaterThanEqual(n, size)))
                continue;
              const double w = (dx ? f.x : 1 - f.x) * (dy ? f.y : 1 - f.y) * (dz ? f.z : 1 - f.z);
              d.values[d.index(n.x, n.y, n.z)] += w * value;
            }
      }
    });
  }
}

template void splatValues<glm::dvec4>(GridOf<glm::dvec4>&, const std::vector<glm::dvec3>&,
                                      const std::vector<glm::dvec4>&, SplatEntries<glm::dvec4>&);

}  // namespace hairgen
