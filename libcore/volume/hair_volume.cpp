#include "libcore/volume/hair_volume.h"

#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <cstdio>
#include <limits>
#include <utility>

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>
#include <tbb/task_arena.h>

#include "libcore/model/mesh.h"
#include "libcore/util/error.h"
#include "libcore/util/vectorise.h"

namespace hairgen {

namespace {

// Calls corner(w, i, j, k) for the 8 nodes around p (clamped to the grid) with their trilinear weights,
// z outermost and x innermost.
template <class G, class Corner>
void forEachCorner(const G& grid, const glm::dvec3& p, Corner corner) {
  glm::dvec3 g =
      glm::clamp((p - grid.origin) / grid.voxel, glm::dvec3(0.0), glm::dvec3(grid.size - 1) - 1e-9);
  glm::ivec3 c = glm::ivec3(glm::floor(g));
  glm::dvec3 f = g - glm::dvec3(c);
  for (int dz = 0; dz < 2; ++dz)
    for (int dy = 0; dy < 2; ++dy)
      for (int dx = 0; dx < 2; ++dx) {
        double w = (dx ? f.x : 1 - f.x) * (dy ? f.y : 1 - f.y) * (dz ? f.z : 1 - f.z);
        corner(w, std::min(c.x + dx, grid.size.x - 1), std::min(c.y + dy, grid.size.y - 1),
               std::min(c.z + dz, grid.size.z - 1));
      }
}

// Σ over the 8 nodes around p of their trilinear weight times value(i, j, k) (p clamped to the grid).
template <class T, class G, class Value>
T trilinear(const G& grid, const glm::dvec3& p, Value value) {
  T out(0.0);
  forEachCorner(grid, p, [&](double w, int i, int j, int k) { out += w * value(i, j, k); });
  return out;
}

}  // namespace

template <class T>
typename GridOf<T>::Sample GridOf<T>::sample(const glm::dvec3& p) const {
  if (size.x < 2 || size.y < 2 || size.z < 2)
    return trilinear<Sample>(*this, p, [&](int i, int j, int k) { return Sample(at(i, j, k)); });
  // trilinear's operations in its order, with the cell found once: g < size − 1, so the cell's far
  // corners are inside the grid and need no clamp (the min only matters past 2²⁴ nodes an axis, where
  // size − 1 − 1e-9 rounds to size − 1).
  const glm::dvec3 g = glm::clamp((p - origin) / voxel, glm::dvec3(0.0), glm::dvec3(size - 1) - 1e-9);
  const glm::ivec3 c = glm::min(glm::ivec3(glm::floor(g)), size - 2);
  const glm::dvec3 f = g - glm::dvec3(c);
  const size_t row = size_t(size.x), slab = row * size_t(size.y);
  const T* corner = &values[index(c.x, c.y, c.z)];
  Sample out(0.0);
  for (int dz = 0; dz < 2; ++dz)
    for (int dy = 0; dy < 2; ++dy) {
      const T* at = corner + size_t(dz) * slab + size_t(dy) * row;
      const double wy = dy ? f.y : 1 - f.y, wz = dz ? f.z : 1 - f.z;
      out += ((1 - f.x) * wy * wz) * Sample(at[0]);
      out += (f.x * wy * wz) * Sample(at[1]);
    }
  return out;
}

namespace {

// Central differences at every node, computed once; the gradient at a point is their trilinear
// interpolant (sampleGradient), 8 lookups.
std::vector<glm::vec3> nodeGradients(const Grid& grid) {
  const glm::ivec3 n = grid.size;
  const float scale = float(1.0 / (2.0 * grid.voxel));
  std::vector<glm::vec3> out(grid.values.size());
  tbb::parallel_for(0, n.z, [&](int k) {
    auto v = [&](int a, int b, int c) {
      return grid.at(std::clamp(a, 0, n.x - 1), std::clamp(b, 0, n.y - 1), std::clamp(c, 0, n.z - 1));
    };
    for (int j = 0; j < n.y; ++j)
      for (int i = 0; i < n.x; ++i)
        out[grid.index(i, j, k)] =
            scale * glm::vec3(v(i + 1, j, k) - v(i - 1, j, k), v(i, j + 1, k) - v(i, j - 1, k),
                              v(i, j, k + 1) - v(i, j, k - 1));
  });
  return out;
}

glm::dvec3 sampleGradient(const Grid& grid, const glm::vec3* gradients, const glm::dvec3& p) {
  return trilinear<glm::dvec3>(
      grid, p, [&](int i, int j, int k) { return glm::dvec3(gradients[grid.index(i, j, k)]); });
}

// grid.sample(p) and sampleGradient(grid, gradients, p) in one pass over the cell: the same weights and
// the same sums, so the same bits as the two calls, for half the finding of the cell and its weights.
struct ValueAndGradient {
  double value = 0.0;
  glm::dvec3 gradient{0.0};
};
ValueAndGradient sampleWithGradient(const Grid& grid, const glm::vec3* gradients, const glm::dvec3& p) {
  ValueAndGradient out;
  forEachCorner(grid, p, [&](double w, int i, int j, int k) {
    const size_t node = grid.index(i, j, k);
    out.value += w * double(grid.values[node]);
    out.gradient += w * glm::dvec3(gradients[node]);
  });
  return out;
}

}  // namespace

Bounds boundsInParallel(std::span<const glm::vec3> points) {
  if (points.empty()) return {};
  const Bounds none{glm::vec3(std::numeric_limits<float>::max()),
                    glm::vec3(std::numeric_limits<float>::lowest())};
  // parallel_reduce joins the boxes of neighbouring ranges left to right, and glm::min and max keep
  // the left of two equal values (+0 and −0): the serial loop's choices.
  return tbb::parallel_reduce(
      tbb::blocked_range<size_t>(0, points.size(), 65536), none,
      [&](const tbb::blocked_range<size_t>& r, Bounds b) {
        for (size_t i = r.begin(); i < r.end(); ++i) {
          b.min = glm::min(b.min, points[i]);
          b.max = glm::max(b.max, points[i]);
        }
        return b;
      },
      [](const Bounds& a, const Bounds& b) {
        return Bounds{glm::min(a.min, b.min), glm::max(a.max, b.max)};
      });
}

template <class T>
GridOf<T> gridAround(std::span<const glm::vec3> points, double voxel, int padding) {
  if (points.empty()) throw InputError("the coupe has no points to build a volume from");
  const Bounds box = boundsInParallel(points);
  const glm::dvec3 lo(box.min), hi(box.max);
  GridOf<T> g;
  g.voxel = voxel;
  g.origin = lo - double(padding) * voxel;
  glm::dvec3 cells = glm::ceil((hi - lo) / voxel) + 1.0 + 2.0 * padding;
  if (cells.x * cells.y * cells.z > 4.0e8) {
    const glm::dvec3 span = hi - lo;
    char text[160];
    std::snprintf(text, sizeof text,
                  "the hair spans %.3g x %.3g x %.3g, which at VoxelSize %.3g is %.3g voxels (4e8 at most)",
                  span.x, span.y, span.z, voxel, cells.x * cells.y * cells.z);
    throw InputError(std::string(text) + "; raise Render.VoxelSize, or check the cache is in metres");
  }
  g.size = glm::ivec3(cells);
  g.values.assign(size_t(g.size.x) * g.size.y * g.size.z, T(0.0f));
  return g;
}

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

template <class T>
void smoothInPlace(GridOf<T>& g) {
  // Separable [1 2 1]/4 along x, y and z, edges clamped (an edge node keeps 3/4 of itself and gives
  // its neighbour 1/4, as that neighbour gives it: the matrix stays symmetric). Line by line through a
  // copy of the line; lines are independent, so any thread count gives the same bits.
  using Scalar = std::conditional_t<std::is_same_v<T, float>, float, double>;
  const Scalar quarter = Scalar(0.25), half = Scalar(0.5);
  const glm::ivec3 n = g.size;
  for (int axis = 0; axis < 3; ++axis) {
    const size_t stride = axis == 0 ? 1 : axis == 1 ? size_t(n.x) : size_t(n.x) * size_t(n.y);
    const int length = n[axis], u = (axis + 1) % 3, w = (axis + 2) % 3;
    tbb::parallel_for(0, n[w], [&](int cw) {
      std::vector<T> line(static_cast<size_t>(length));
      for (int cu = 0; cu < n[u]; ++cu) {
        glm::ivec3 c(0);
        c[u] = cu;
        c[w] = cw;
        T* first = &g.values[g.index(c.x, c.y, c.z)];
        for (int t = 0; t < length; ++t) line[size_t(t)] = first[size_t(t) * stride];
        for (int t = 0; t < length; ++t)
          first[size_t(t) * stride] = quarter * line[size_t(std::max(t - 1, 0))] + half * line[size_t(t)] +
                                      quarter * line[size_t(std::min(t + 1, length - 1))];
      }
    });
  }
}

template <class T>
GridOf<T> smoothed(const GridOf<T>& g) {
  GridOf<T> out = g;
  smoothInPlace(out);
  return out;
}

glm::dvec3 densityForce(const Grid& d, const glm::dvec3& p) {
  const glm::dvec3 g = (p - d.origin) / d.voxel;
  const glm::ivec3 c = glm::ivec3(glm::floor(g));
  if (glm::any(glm::lessThan(c, glm::ivec3(0))) || glm::any(glm::greaterThanEqual(c + 1, d.size)))
    return glm::dvec3(0.0);
  const glm::dvec3 f = g - glm::dvec3(c);
  auto at = [&](int dx, int dy, int dz) { return double(d.at(c.x + dx, c.y + dy, c.z + dz)); };
  // The memo's weights of the cell's lower grid lines, a = 1 − f: F_x differences D_d across the cell
  // in x, weighted by the point's tent weights in y and z; F_y and F_z likewise.
  const glm::dvec3 a = 1.0 - f;
  glm::dvec3 force(0.0);
  if (f.x != 0.0)
    force.x = a.y * a.z * (at(0, 0, 0) - at(1, 0, 0)) + (1 - a.y) * a.z * (at(0, 1, 0) - at(1, 1, 0)) +
              a.y * (1 - a.z) * (at(0, 0, 1) - at(1, 0, 1)) +
              (1 - a.y) * (1 - a.z) * (at(0, 1, 1) - at(1, 1, 1));
  if (f.y != 0.0)
    force.y = a.x * a.z * (at(0, 0, 0) - at(0, 1, 0)) + (1 - a.x) * a.z * (at(1, 0, 0) - at(1, 1, 0)) +
              a.x * (1 - a.z) * (at(0, 0, 1) - at(0, 1, 1)) +
              (1 - a.x) * (1 - a.z) * (at(1, 0, 1) - at(1, 1, 1));
  if (f.z != 0.0)
    force.z = a.x * a.y * (at(0, 0, 0) - at(0, 0, 1)) + (1 - a.x) * a.y * (at(1, 0, 0) - at(1, 0, 1)) +
              a.x * (1 - a.y) * (at(0, 1, 0) - at(0, 1, 1)) +
              (1 - a.x) * (1 - a.y) * (at(1, 1, 0) - at(1, 1, 1));
  return force;
}

double densityEnergy(const Grid& d) {
  double sum = 0.0;
  for (float v : d.values) sum += double(v) * double(v);
  return 0.5 * sum;
}

template struct GridOf<float>;
template struct GridOf<glm::dvec4>;
template GridOf<float> gridAround<float>(std::span<const glm::vec3>, double, int);
template GridOf<glm::dvec4> gridAround<glm::dvec4>(std::span<const glm::vec3>, double, int);
template void smoothInPlace<float>(GridOf<float>&);
template void smoothInPlace<glm::dvec4>(GridOf<glm::dvec4>&);
template GridOf<float> smoothed<float>(const GridOf<float>&);
template GridOf<glm::dvec4> smoothed<glm::dvec4>(const GridOf<glm::dvec4>&);
template void splatValues<glm::dvec4>(GridOf<glm::dvec4>&, const std::vector<glm::dvec3>&,
                                      const std::vector<glm::dvec4>&, SplatEntries<glm::dvec4>&);

namespace {

constexpr double kNone = std::numeric_limits<double>::infinity();  // a node with no shell point yet

// One x-line of fast sweeping in one of the 8 orders of the axes (bit 0, 1, 2 of `order` reverse x, y,
// z): each node takes the nearest point of a neighbour behind it when that is nearer than its own. `jj`
// and `kk` count lines in the order's direction. Built for AVX2 as well, as slideSlab is.
HAIRGEN_VECTOR_CLONES __attribute__((flatten)) void sweepLine(const glm::ivec3& n, const glm::dvec3& origin,
                                                              double h, int order, int jj, int kk,
                                                              glm::dvec3* nearest, double* dist2) {
  const bool fx = order & 1, fy = order & 2, fz = order & 4;
  const size_t strideY = size_t(n.x), strideZ = size_t(n.x) * n.y;
  for (int ii = 0; ii < n.x; ++ii) {
    const int i = fx ? n.x - 1 - ii : ii, j = fy ? n.y - 1 - jj : jj, k = fz ? n.z - 1 - kk : kk;
    const size_t id = (size_t(k) * n.y + j) * n.x + i;
    const glm::dvec3 x = origin + h * glm::dvec3(i, j, k);
    const bool has[3] = {fx ? i + 1 < n.x : i > 0, fy ? j + 1 < n.y : j > 0, fz ? k + 1 < n.z : k > 0};
    const size_t behind[3] = {fx ? id + 1 : id - 1, fy ? id + strideY : id - strideY,
                              fz ? id + strideZ : id - strideZ};
    for (int axis = 0; axis < 3; ++axis) {
      if (!has[axis] || dist2[behind[axis]] == kNone) continue;
      const glm::dvec3 e = nearest[behind[axis]] - x;
      const double d2 = glm::dot(e, e);
      if (d2 < dist2[id]) nearest[id] = nearest[behind[axis]], dist2[id] = d2;
    }
  }
}

// Newton's steps on the trilinear φ = density − iso, p ← p − φ ∇φ/|∇φ|², from p back onto the shell;
// false when they do not reach it within `tolerance`. Leaves in `gradient` ∇φ at the point it returns,
// which the slide's next round starts from.
inline bool ontoShell(const Grid& density, const glm::vec3* gradients, double iso, double tolerance,
                      glm::dvec3& p, glm::dvec3& gradient) {
  ValueAndGradient at = sampleWithGradient(density, gradients, p);
  double value = at.value - iso;
  for (int step = 0; step < 16 && std::abs(value) > tolerance; ++step) {
    const glm::dvec3 g = at.gradient;
    const double g2 = glm::dot(g, g);
    if (!(g2 > 0.0)) return false;
    p -= (value / g2) * g;
    at = sampleWithGradient(density, gradients, p);
    value = at.value - iso;
  }
  gradient = at.gradient;
  return std::abs(value) <= tolerance;
}

// Slides the nearest shell point of every node of z-slab k (every flagged one, with `exactAt`) along the
// shell until x − p lies along the shell's normal at p, the condition for the nearest point: a step along the
// tangent plane, then ontoShell; kept while the distance falls. Most of signedDistance's time: built for AVX2
// as well and flattened, so the sampling it calls is built with it (the same scalar arithmetic in the same
// order, with floor one instruction instead of a dozen and the cell's loads and weights scheduled together).
HAIRGEN_VECTOR_CLONES __attribute__((flatten)) void slideSlab(const Grid& density, const glm::vec3* gradients,
                                                              double iso, double tolerance, int k,
                                                              const uint8_t* exactAt, glm::dvec3* nearest,
                                                              double* dist2) {
  const glm::ivec3 n = density.size;
  const double h = density.voxel;
  for (int j = 0; j < n.y; ++j)
    for (int i = 0; i < n.x; ++i) {
      const size_t id = density.index(i, j, k);
      if (dist2[id] == kNone || (exactAt && !exactAt[id])) continue;
      const glm::dvec3 x = density.origin + h * glm::dvec3(i, j, k);
      glm::dvec3 g = sampleGradient(density, gradients, nearest[id]);
      for (int round = 0; round < 6; ++round) {
        const glm::dvec3 p = nearest[id];
        const double g2 = glm::dot(g, g);
        if (!(g2 > 0.0)) break;
        glm::dvec3 across = (x - p) - glm::dot(x - p, g) / g2 * g;
        const double a2 = glm::dot(across, across);
        if (a2 <= 1e-6 * dist2[id]) break;
        if (a2 > h * h) across *= h / std::sqrt(a2);
        glm::dvec3 q = p + across, gq;
        if (!ontoShell(density, gradients, iso, tolerance, q, gq)) break;
        const double d2 = glm::dot(q - x, q - x);
        if (!(d2 < dist2[id])) break;
        nearest[id] = q, dist2[id] = d2, g = gq;
      }
    }
}

}  // namespace

Grid signedDistance(const Grid& density, double iso, const std::vector<uint8_t>* exactAt) {
  const glm::ivec3 n = density.size;
  const double h = density.voxel;
  const size_t count = density.values.size();
  auto node = [&](int i, int j, int k) { return density.origin + h * glm::dvec3(i, j, k); };
  std::vector<char> inside(count);
  for (size_t i = 0; i < count; ++i) inside[i] = density.values[i] > iso;

  // Every node carries the nearest point of the shell it knows of. It starts at the nodes with an
  // edge across the shell, as the nearest crossing of φ = density − iso along their own edges (by
  // linear interpolation, which is exact on the trilinear φ).
  std::vector<glm::dvec3> nearest(count, glm::dvec3(kNone));
  std::vector<double> dist2(count, kNone);
  tbb::parallel_for(0, n.z, [&](int k) {
    for (int j = 0; j < n.y; ++j)
      for (int i = 0; i < n.x; ++i) {
        const size_t id = density.index(i, j, k);
        const double f = density.values[id] - iso;
        for (int axis = 0; axis < 3; ++axis)
          for (int side = -1; side <= 1; side += 2) {
            glm::ivec3 b(i, j, k);
            b[axis] += side;
            if (b[axis] < 0 || b[axis] >= n[axis]) continue;
            const size_t nb = density.index(b.x, b.y, b.z);
            if (inside[nb] == inside[id]) continue;
            const double t = f / (f - (density.values[nb] - iso));
            if (t * t * h * h >= dist2[id]) continue;
            nearest[id] = node(i, j, k);
            nearest[id][axis] += side * t * h;
            dist2[id] = t * t * h * h;
          }
      }
  });

  // Fast sweeping of the nearest points (a closest-point transform): in each of the 8 orders of the
  // axes a node takes the nearest point of a neighbour behind it when that is nearer than its own.
  // A node reads only the neighbours behind it in the order, each already swept in it, and writes only
  // itself; so the x-lines (jj, kk) on one diagonal jj + kk = d depend on the diagonal before alone,
  // and sweeping the diagonals in turn, their lines at once, gives the bits of the raster order.
  auto sweep = [&] {  // one round of the 8 orders: the slide below mends what it leaves
    for (int order = 0; order < 8; ++order)
      for (int d = 0; d <= (n.y - 1) + (n.z - 1); ++d)
        tbb::parallel_for(std::max(0, d - (n.y - 1)), std::min(d, n.z - 1) + 1, [&](int kk) {
          sweepLine(density.size, density.origin, h, order, d - kk, kk, nearest.data(), dist2.data());
        });
  };

  // A nearest point carried from a neighbour is a shell point near the node's own nearest point, not
  // that point: off by up to a voxel along the shell, which makes the distance too long and ∇S wrong.
  // Each node slides its point along the shell (slideSlab).
  const double tolerance = 1e-4 * std::abs(iso) + 1e-12;
  const std::vector<glm::vec3> gradients = nodeGradients(density);
  auto slide = [&] {
    tbb::parallel_for(0, n.z, [&](int k) {
      slideSlab(density, gradients.data(), iso, tolerance, k, exactAt ? exactAt->data() : nullptr,
                nearest.data(), dist2.data());
    });
  };
  sweep();
  slide();

  Grid s = density;
  const double far = h * (n.x + n.y + n.z);  // a grid without a shell: everything is far outside or inside
  for (size_t i = 0; i < count; ++i) {
    const double d = dist2[i] == kNone ? far : std::sqrt(dist2[i]);
    s.values[i] = static_cast<float>(inside[i] ? -d : d);
  }
  return s;
}

double typicalDensity(const Grid& density) {
  double sum = 0.0, squares = 0.0;
  for (float v : density.values) sum += v, squares += double(v) * v;
  return sum > 0.0 ? squares / sum : 0.0;
}

HairVolume buildVolume(const Strands& strands, double voxel, int padding, double shellFraction,
                       bool distanceEverywhere) {
  HairVolume volume;
  volume.density = gridAround(strands.points, voxel, padding);
  splat(volume.density, strands.points);
  const Grid smooth = smoothed(volume.density);
  volume.iso = shellFraction * typicalDensity(smooth);
  volume.distanceEverywhere = distanceEverywhere;
  if (distanceEverywhere) {
    volume.distance = signedDistance(smooth, volume.iso);
  } else {
    const std::vector<uint8_t> read = nodesNormalsRead(smooth, strands.points);
    volume.distance = signedDistance(smooth, volume.iso, &read);
  }
  return volume;
}

namespace {

// One corner of the trilinear interpolant for a block of points (sampleGradient's loop body, dz, dy, dx
// fixed): out += w · gradient at the corner, with trilinear's weight and clamped index.
template <int dx, int dy, int dz>
inline __attribute__((always_inline)) void addCorner(size_t count, const int sx, const int sy, const int sz,
                                                     const glm::vec3* __restrict gradients,
                                                     const int* __restrict cx, const int* __restrict cy,
                                                     const int* __restrict cz, const double* __restrict fx,
                                                     const double* __restrict fy, const double* __restrict fz,
                                                     double* __restrict ox, double* __restrict oy,
                                                     double* __restrict oz) {
  HAIRGEN_IVDEP
  for (size_t p = 0; p < count; ++p) {
    const double w = (dx ? fx[p] : 1 - fx[p]) * (dy ? fy[p] : 1 - fy[p]) * (dz ? fz[p] : 1 - fz[p]);
    const int i = std::min(cx[p] + dx, sx - 1), j = std::min(cy[p] + dy, sy - 1),
              k = std::min(cz[p] + dz, sz - 1);
    const int node = (k * sy + j) * sx + i;  // fewer than 2^31 nodes (gridAround)
    ox[p] = ox[p] + w * double(gradients[node].x);
    oy[p] = oy[p] + w * double(gradients[node].y);
    oz[p] = oz[p] + w * double(gradients[node].z);
  }
}

constexpr size_t kNormalsBlock = 256;  // points a block

// The eight corners with x fastest, then y, then z: the order the one-point-at-a-time sum adds them. A
// function forced inline, not a lambda: a lambda is a function of its own, built for the baseline, and
// would run the corners without the caller's AVX2.
template <int... k>
inline __attribute__((always_inline)) void addCorners(std::integer_sequence<int, k...>, size_t count,
                                                      const glm::ivec3& size,
                                                      const glm::vec3* __restrict gradients,
                                                      const int* __restrict c, const double* __restrict f,
                                                      double* __restrict out) {
  constexpr size_t kB = kNormalsBlock;
  ((addCorner<(k & 1), ((k >> 1) & 1), (k >> 2)>(count, size.x, size.y, size.z, gradients, c, c + kB,
                                                 c + 2 * kB, f, f + kB, f + 2 * kB, out, out + kB,
                                                 out + 2 * kB)),
   ...);
}

// The cells of up to 256 points (axis by axis, kNormalsBlock apart in `c`) and their fractions within
// them (`f`): the truncated grid coordinate, clamped. Inlined into its callers, so each is built for
// their instruction sets and the two find the same cells.
inline __attribute__((always_inline)) void cellsOfBlock(const Grid& grid, const glm::vec3* __restrict points,
                                                        size_t count, int* __restrict c,
                                                        double* __restrict f) {
  constexpr size_t kB = kNormalsBlock;
  const glm::dvec3 top = glm::dvec3(grid.size - 1) - 1e-9;
  const float* const xyz = &points[0].x;
  for (int axis = 0; axis < 3; ++axis) {
    const double origin = grid.origin[axis], voxel = grid.voxel, hi = top[axis];
    HAIRGEN_IVDEP
    for (size_t p = 0; p < count; ++p) {
      double g = (double(xyz[3 * p + axis]) - origin) / voxel;
      g = g < 0.0 ? 0.0 : g;  // glm::clamp: min(max(g, 0), hi)
      g = hi < g ? hi : g;
      const int cell = static_cast<int>(g);
      c[axis * kB + p] = cell;
      f[axis * kB + p] = g - double(cell);
    }
  }
}

// Flags the cell of each of up to 256 points (nodesNormalsRead). Threads may flag one cell together:
// the same byte, written atomically.
HAIRGEN_VECTOR_CLONES
void flagCellsOfBlock(const Grid& grid, const glm::vec3* __restrict points, size_t count, uint8_t* cells) {
  constexpr size_t kB = kNormalsBlock;
  int c[3 * kB];
  double f[3 * kB];
  cellsOfBlock(grid, points, count, c, f);
  for (size_t p = 0; p < count; ++p)
    std::atomic_ref<uint8_t>(cells[grid.index(c[p], c[kB + p], c[2 * kB + p])])
        .store(1, std::memory_order_relaxed);
}

// Normals ∇S/|∇S| of up to 256 points: sampleGradient and the normalisation of volumeNormals, one stage
// at a time over the block so each runs across points in vector registers (libcore/util/vectorise.h),
// with the arithmetic of trilinear() per point. The cell is the truncation of the clamped grid
// coordinate: it is never negative, where truncating is flooring.
HAIRGEN_VECTOR_CLONES
void normalsOfBlock(const Grid& grid, const glm::vec3* __restrict gradients,
                    const glm::vec3* __restrict points, size_t count, glm::vec3* __restrict normals) {
  constexpr size_t kB = kNormalsBlock;
  int c[3 * kB];
  double f[3 * kB], out[3 * kB] = {};
  cellsOfBlock(grid, points, count, c, f);
  addCorners(std::make_integer_sequence<int, 8>{}, count, grid.size, gradients, c, f, out);
  float* const n = &normals[0].x;
  double* const lengths = f;  // the fractions are spent
  HAIRGEN_IVDEP
  for (size_t p = 0; p < count; ++p) {
    const double x = out[p], y = out[kB + p], z = out[2 * kB + p];
    const double len = std::sqrt((x * x + y * y) + z * z);
    lengths[p] = len;
    n[3 * p] = static_cast<float>(x / len);
    n[3 * p + 1] = static_cast<float>(y / len);
    n[3 * p + 2] = static_cast<float>(z / len);
  }
  for (size_t p = 0; p < count; ++p)  // no gradient (a flat distance): +y, as every vertex must have one
    if (!(lengths[p] > 1e-12)) normals[p] = glm::vec3(0, 1, 0);
}

}  // namespace

std::vector<glm::vec3> volumeNormals(const Grid& distance, const Strands& strands) {
  std::vector<glm::vec3> normals;
  volumeNormals(distance, strands, normals);
  return normals;
}

void volumeNormals(const Grid& distance, const Strands& strands, std::vector<glm::vec3>& normals) {
  const std::vector<glm::vec3> gradients = nodeGradients(distance);
  normals.resize(strands.pointCount());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, strands.pointCount(), 8192),
                    [&](const tbb::blocked_range<size_t>& r) {
                      for (size_t p = r.begin(); p < r.end(); p += kNormalsBlock)
                        normalsOfBlock(distance, gradients.data(), &strands.points[p],
                                       std::min(kNormalsBlock, r.end() - p), &normals[p]);
                    });
}

std::vector<uint8_t> nodesNormalsRead(const Grid& grid, std::span<const glm::vec3> points) {
  const glm::ivec3 n = grid.size;
  const size_t count = grid.values.size();
  // Each point's cell, found as normalsOfBlock finds it, flagged at its lowest corner.
  std::vector<uint8_t> cells(count, 0);
  tbb::parallel_for(
      tbb::blocked_range<size_t>(0, points.size(), 8192), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t p = r.begin(); p < r.end(); p += kNormalsBlock)
          flagCellsOfBlock(grid, &points[p], std::min(kNormalsBlock, r.end() - p), cells.data());
      });
  // The cells' corners (clamped to the grid, as addCorner clamps them: a clamped corner is the cell's
  // node or one beyond it, each flagged below), then their axis neighbours (clamped, as nodeGradients
  // clamps them).
  std::vector<uint8_t> corners(count, 0), read(count, 0);
  auto clampedIndex = [&](int i, int j, int k) {
    return grid.index(std::clamp(i, 0, n.x - 1), std::clamp(j, 0, n.y - 1), std::clamp(k, 0, n.z - 1));
  };
  tbb::parallel_for(0, n.z, [&](int k) {
    for (int j = 0; j < n.y; ++j)
      for (int i = 0; i < n.x; ++i) {
        uint8_t any = 0;
        for (int d = 0; d < 8; ++d) {
          const int ci = i - (d & 1), cj = j - ((d >> 1) & 1), ck = k - (d >> 2);
          if (ci >= 0 && cj >= 0 && ck >= 0) any |= cells[grid.index(ci, cj, ck)];
        }
        corners[grid.index(i, j, k)] = any;
      }
  });
  tbb::parallel_for(0, n.z, [&](int k) {
    for (int j = 0; j < n.y; ++j)
      for (int i = 0; i < n.x; ++i)
        read[grid.index(i, j, k)] = corners[grid.index(i, j, k)] | corners[clampedIndex(i - 1, j, k)] |
                                    corners[clampedIndex(i + 1, j, k)] | corners[clampedIndex(i, j - 1, k)] |
                                    corners[clampedIndex(i, j + 1, k)] | corners[clampedIndex(i, j, k - 1)] |
                                    corners[clampedIndex(i, j, k + 1)];
  });
  return read;
}

}  // namespace hairgen
