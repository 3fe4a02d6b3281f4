#include "libcore/volume/shell.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <utility>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "libcore/util/error.h"
#include "libcore/util/vectorise.h"
#include "libcore/volume/splat.h"

namespace hairgen {

using grid_detail::forEachCorner;
using grid_detail::trilinear;

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
