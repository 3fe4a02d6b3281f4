// interpolate: Lansink 2010 §4.1.4.3-4.1.4.4. Per wick triangle, area × HairDensity strands; each
// strand's root weights are uniform barycentrics, its tip weights clump to the corner guide nearest
// the root, and the weights blend linearly from root to tip over the strand's vertices.
#include "stages/interpolate.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>

#include "libcore/util/error.h"
#include "libcore/util/huge_pages.h"
#include "libcore/util/random.h"
#include "libcore/util/text.h"
#include "libcore/util/vectorise.h"
#include "stages/preflight/estimate.h"

namespace hairgen {
namespace {

// The random streams of one key (seed, triangle, strand).
enum Stream : uint64_t { kRootU1, kRootU2, kTipV1, kTipV2, kCountFraction };
constexpr uint64_t kTriangleKey = std::numeric_limits<uint64_t>::max();  // "strand" of per-triangle numbers

// Normalised arc length of every vertex of a polyline; all zero when it has no length.
std::vector<double> normalisedArcLength(const glm::vec3* p, uint32_t count) {
  std::vector<double> u(count, 0.0);
  for (uint32_t i = 1; i < count; ++i) u[i] = u[i - 1] + glm::length(glm::dvec3(p[i]) - glm::dvec3(p[i - 1]));
  double total = count > 0 ? u[count - 1] : 0.0;
  for (double& v : u) v = total > 0.0 ? v / total : 0.0;
  return u;
}

// Samples a polyline at normalised arc lengths `at`, linearly between its vertices.
void resample(const glm::vec3* p, const glm::vec3* t, uint32_t count, const std::vector<double>& at,
              std::vector<glm::vec3>& points, std::vector<glm::vec3>& tangents) {
  std::vector<double> u = normalisedArcLength(p, count);
  points.resize(at.size());
  tangents.resize(at.size());
  size_t seg = 0;
  for (size_t i = 0; i < at.size(); ++i) {
    while (seg + 2 < count && u[seg + 1] < at[i]) ++seg;
    if (count == 1 || u[count - 1] == 0.0) {
      points[i] = p[0];
      tangents[i] = t[0];
      continue;
    }
    double span = u[seg + 1] - u[seg];
    double f = span > 0.0 ? std::clamp((at[i] - u[seg]) / span, 0.0, 1.0) : 0.0;
    points[i] = glm::vec3(glm::mix(glm::dvec3(p[seg]), glm::dvec3(p[seg + 1]), f));
    glm::vec3 tangent = glm::mix(t[seg], t[seg + 1], static_cast<float>(f));
    float len = glm::length(tangent);
    tangents[i] = len > 0.0f ? tangent / len : t[seg];
  }
}

void checkGuides(const Mesh& wick, const Strands& guides, const std::string& name, const glm::dmat4& pose) {
  const FileLoc where{name, 0};
  if (guides.strandCount() != wick.vertexCount())
    throw InputError(where, "has " + std::to_string(guides.strandCount()) + " guides but the wick has " +
                                std::to_string(wick.vertexCount()) +
                                " vertices; interpolate needs the guides grown from this Setup's wick");
  for (size_t i = 0; i < guides.strandCount(); ++i) {
    if (guides.pointsOf(i) == 0) throw InputError(where, "guide " + std::to_string(i) + " has no points");
    if (!guides.strandId.empty() && guides.strandId[i] != i)
      throw InputError(where, "guide " + std::to_string(i) + " has id " + std::to_string(guides.strandId[i]) +
                                  "; guides must be in the wick's vertex order");
    const glm::dvec3 vertex(pose * glm::dvec4(glm::dvec3(wick.positions[i]), 1.0));
    double gap = glm::length(glm::dvec3(guides.points[guides.firstPoint[i]]) - vertex);
    if (!(gap <= 1e-4)) {
      throw InputError(where, "guide " + std::to_string(i) + " starts " + formatSignificant(gap * 1e3) +
                                  " mm from wick vertex " + std::to_string(i) +
                                  "; these guides were not grown from this Setup's wick");
    }
  }
}

}  // namespace

uint32_t strandsInTriangle(double areaCm2, double density, double u) {
  double n = areaCm2 * density;
  // More than 32 bits hold is saturated, and refused by the caller's offset check; converting such a
  // double to uint32_t would be undefined.
  if (!(n < double(std::numeric_limits<uint32_t>::max()))) return std::numeric_limits<uint32_t>::max();
  double whole = std::floor(n);
  return static_cast<uint32_t>(whole) + (u < n - whole ? 1u : 0u);
}

glm::dvec3 rootWeights(double u1, double u2) {
  if (u1 + u2 > 1.0) {
    u1 = 1.0 - u1;
    u2 = 1.0 - u2;
  }
  return {u1, u2, 1.0 - (u1 + u2)};
}

glm::dvec3 tipWeights(const glm::dvec3& r, double v1, double v2, bool strayHairs) {
  if (v1 + v2 > 1.0) {
    if (v1 > v2)
      v1 = 1.0 - v1;
    else
      v2 = 1.0 - v2;
  }
  const double v3 = 1.0 - (v1 + v2);
  if (strayHairs) {
    // The thesis' conditions as printed; for three distinct weights they give its Table 4.
    return {r.x < r.y ? v1 : (r.x < r.z ? v2 : v3),  //
            r.y < r.z ? v1 : (r.y < r.x ? v2 : v3),  //
            r.z < r.x ? v1 : (r.z < r.y ? v2 : v3)};
  }
  int nearest = r.x >= r.y && r.x >= r.z ? 0 : (r.y >= r.z ? 1 : 2);
  glm::dvec3 w;
  w[nearest] = v3;
  w[(nearest + 1) % 3] = v1;
  w[(nearest + 2) % 3] = v2;
  return w;
}

namespace {

// The blend of one strand, written as for one vertex at a time: w = root + (tip − root)·f, p = centre + Σ w_c
// (guide_c − centre), t = 0 + Σ w_c tangent_c, |t| = sqrt((x² + y²) + z²), t/|t| — the same operations in the
// same order on every value, so the compiler may run them across vertices in vector registers and the bits
// are those of one at a time. No fused multiply-add (libcore/util/vectorise.h).
HAIRGEN_VECTOR_CLONES
void blendVertices(const double* __restrict soa, uint32_t count, const double* root, const double* step,
                   const double* centre, float* __restrict points, float* __restrict tangents,
                   double* __restrict lengths) {
  const size_t n = count;
  const double* a[18];  // per guide: offsets x, y, z, tangents x, y, z
  for (size_t k = 0; k < 18; ++k) a[k] = soa + k * n;
  const double* const fraction = soa + 18 * n;
  const double r0 = root[0], r1 = root[1], r2 = root[2], s0 = step[0], s1 = step[1], s2 = step[2];
  const double c0 = centre[0], c1 = centre[1], c2 = centre[2];
  HAIRGEN_IVDEP
  for (size_t i = 0; i < n; ++i) {
    const double f = fraction[i];
    const double w0 = r0 + s0 * f, w1 = r1 + s1 * f, w2 = r2 + s2 * f;
    double px = c0 + w0 * a[0][i], py = c1 + w0 * a[1][i], pz = c2 + w0 * a[2][i];
    px = px + w1 * a[6][i], py = py + w1 * a[7][i], pz = pz + w1 * a[8][i];
    px = px + w2 * a[12][i], py = py + w2 * a[13][i], pz = pz + w2 * a[14][i];
    double tx = 0.0 + w0 * a[3][i], ty = 0.0 + w0 * a[4][i], tz = 0.0 + w0 * a[5][i];
    tx = tx + w1 * a[9][i], ty = ty + w1 * a[10][i], tz = tz + w1 * a[11][i];
    tx = tx + w2 * a[15][i], ty = ty + w2 * a[16][i], tz = tz + w2 * a[17][i];
    const double len = std::sqrt((tx * tx + ty * ty) + tz * tz);
    lengths[i] = len;
    points[3 * i] = static_cast<float>(px);  // the coupe's layout, each vertex written once
    points[3 * i + 1] = static_cast<float>(py);
    points[3 * i + 2] = static_cast<float>(pz);
    tangents[3 * i] = static_cast<float>(tx / len);
    tangents[3 * i + 1] = static_cast<float>(ty / len);
    tangents[3 * i + 2] = static_cast<float>(tz / len);
  }
}

}  // namespace

void TriangleBlend::prepare(const GuideSpan (&g)[3], uint32_t n, const glm::dvec3& centre) {
  for (int c = 0; c < 3; ++c) guides_[c] = g[c];
  n_ = n;
  centre_ = centre;
  soa_.resize(19 * size_t(n));
  lengths_.resize(n);
  for (int c = 0; c < 3; ++c) {
    double* a = soa_.data() + 6 * size_t(c) * n;
    for (uint32_t i = 0; i < n; ++i) {
      for (int axis = 0; axis < 3; ++axis) {
        a[axis * size_t(n) + i] = double(g[c].points[i][axis]) - centre[axis];
        a[(3 + axis) * size_t(n) + i] = double(g[c].tangents[i][axis]);
      }
    }
  }
  // b_i from b_root at the root to b_tip at the tip (the thesis' i/n never reaches the tip).
  double* fraction = soa_.data() + 18 * size_t(n);
  for (uint32_t i = 0; i < n; ++i) fraction[i] = n > 1 ? double(i) / double(n - 1) : 0.0;
}

void TriangleBlend::blend(const glm::dvec3& root, const glm::dvec3& tip, glm::vec3* points,
                          glm::vec3* tangents) {
  const glm::dvec3 step = tip - root;
  blendVertices(soa_.data(), n_, &root.x, &step.x, &centre_.x, &points[0].x, &tangents[0].x, lengths_.data());
  const double* fraction = soa_.data() + 18 * size_t(n_);
  for (uint32_t i = 0; i < n_; ++i) {
    if (lengths_[i] > 1e-12) continue;
    // Opposed tangents cancel only on a pathological blend: keep the heaviest guide's.
    const glm::dvec3 w = root + step * fraction[i];
    const int heaviest = w.x >= w.y && w.x >= w.z ? 0 : (w.y >= w.z ? 1 : 2);
    tangents[i] = guides_[heaviest].tangents[i];
  }
}

glm::dvec3 strayCentre(const Collision& collision) {
  const CollisionShape* head = headShape(collision);
  return head ? head->centre : glm::dvec3(0.0);
}

Strands interpolate(const Mesh& wick, const Strands& guides, const Hairstyle& style,
                    const Collision& collision, const InterpolateOptions& options) {
  Strands coupe;
  interpolateInto(wick, guides, style, collision, options, coupe);
  return coupe;
}

void interpolateInto(const Mesh& wick, const Strands& guides, const Hairstyle& style,
                     const Collision& collision, const InterpolateOptions& options, Strands& coupe) {
  if (wick.triangles.empty())
    throw InputError(
        "the wick has no faces, only points (roots): interpolation spreads strands over a "
        "surface and needs one; give a scalp mesh as WickModel (the guides grown on the points "
        "can still be rendered)");
  checkGuides(wick, guides, options.guidesName, options.pose);
  const size_t triangleCount = wick.triangles.size();
  size_t pointsPerGuide = 0;
  for (size_t g = 0; g < guides.strandCount(); ++g)
    pointsPerGuide = std::max<size_t>(pointsPerGuide, guides.pointsOf(g));
  requireFits(estimateInterpolate(style, surfaceArea(wick) * 1e4, triangleCount, pointsPerGuide),
              options.force);
  const uint64_t seed = style.seed;
  const PointArray guideTangents = tangentsOf(guides);

  // Counts and offsets first, so every triangle writes its own slice of the arrays in parallel.
  std::vector<uint32_t> count(triangleCount), vertices(triangleCount);
  std::vector<uint64_t> firstStrand(triangleCount + 1, 0), firstPoint(triangleCount + 1, 0);
  uint64_t maxCount = 0;
  for (size_t t = 0; t < triangleCount; ++t) {
    const glm::uvec3& tri = wick.triangles[t];
    count[t] = strandsInTriangle(triangleArea(wick, t) * 1e4, style.hairDensity,
                                 counterUniform(seed, t, kTriangleKey, kCountFraction));
    vertices[t] = std::max({guides.pointsOf(tri.x), guides.pointsOf(tri.y), guides.pointsOf(tri.z)});
    firstStrand[t + 1] = firstStrand[t] + count[t];
    firstPoint[t + 1] = firstPoint[t] + uint64_t(count[t]) * vertices[t];
    maxCount = std::max<uint64_t>(maxCount, count[t]);
  }
  if (firstPoint.back() >= std::numeric_limits<uint32_t>::max() ||
      (maxCount > 0 && (maxCount - 1) * triangleCount + triangleCount > std::numeric_limits<uint32_t>::max()))
    throw InputError("HairDensity " + std::to_string(style.hairDensity) + " gives " +
                     std::to_string(firstStrand.back()) + " strands of " + std::to_string(firstPoint.back()) +
                     " points, more than 32-bit offsets and ids can hold; lower HairDensity");

  // A shard holds the strands of its triangles, its offsets counted from its first triangle's.
  const size_t firstTriangle = options.shard ? options.shard->first : 0,
               endTriangle = options.shard ? options.shard->end : triangleCount;
  if (firstTriangle > endTriangle || endTriangle > triangleCount)
    throw InputError("the shard's triangles lie outside the wick's triangles");
  const uint64_t strandBase = firstStrand[firstTriangle], pointBase = firstPoint[firstTriangle];
  const size_t strands = firstStrand[endTriangle] - strandBase, points = firstPoint[endTriangle] - pointBase;
  // Every array is resized, not made anew: a coupe of the same size (the next frame's) keeps its
  // storage, and every element below is written whatever it held.
  // (The two large arrays at once: resize fills each on one thread.)
  tbb::parallel_invoke([&] { resizeLarge(coupe.points, points); },
                       [&] { resizeLarge(coupe.tangents, points); });
  coupe.firstPoint.resize(strands + 1);
  coupe.strandId.resize(strands);
  coupe.rootTriangle.resize(strands);
  coupe.rootBary.resize(strands);
  coupe.guideIds.resize(strands);
  coupe.guideWeights.resize(strands);
  coupe.rootUv.resize(wick.uvs.empty() ? 0 : strands);
  coupe.firstPoint[strands] = static_cast<uint32_t>(points);
  coupe.normals.clear();  // what shade or a converted cache added; a fresh coupe has none
  coupe.colors.clear();
  coupe.thickness.clear();
  coupe.transparency.clear();
  coupe.simulationState.clear();

  const glm::dvec3 centre(options.pose * glm::dvec4(strayCentre(collision), 1.0));
  // Each thread's scratch: the triangle's guides in double and the resampled guides, reused from
  // triangle to triangle, so no strand and no triangle allocates once a thread's buffers have grown.
  struct Scratch {
    TriangleBlend blend;
    std::vector<glm::vec3> resampledPoints[3], resampledTangents[3];
    std::vector<double> at;
  };
  tbb::enumerable_thread_specific<Scratch> scratch;
  tbb::parallel_for(firstTriangle, endTriangle, [&](size_t t) {
    Scratch& local = scratch.local();
    const glm::uvec3 tri = wick.triangles[t];
    const uint32_t n = vertices[t];
    // Guides with n vertices are read by index (grow samples every guide at the same fractions of its
    // length); a shorter one is resampled at the normalised arc lengths of the first longest guide.
    GuideSpan g[3];
    int reference = guides.pointsOf(tri.x) == n ? 0 : (guides.pointsOf(tri.y) == n ? 1 : 2);
    bool haveAt = false;
    for (int c = 0; c < 3; ++c) {
      const uint32_t first = guides.firstPoint[tri[c]], m = guides.pointsOf(tri[c]);
      if (m == n) {
        g[c] = {&guides.points[first], &guideTangents[first]};
        continue;
      }
      if (!haveAt) local.at = normalisedArcLength(&guides.points[guides.firstPoint[tri[reference]]], n);
      haveAt = true;
      resample(&guides.points[first], &guideTangents[first], m, local.at, local.resampledPoints[c],
               local.resampledTangents[c]);
      g[c] = {local.resampledPoints[c].data(), local.resampledTangents[c].data()};
    }
    local.blend.prepare(g, n, centre);

    for (uint32_t k = 0; k < count[t]; ++k) {
      const size_t s = firstStrand[t] - strandBase + k;
      const glm::dvec3 root =
          rootWeights(counterUniform(seed, t, k, kRootU1), counterUniform(seed, t, k, kRootU2));
      const glm::dvec3 tip = tipWeights(root, style.clump * counterUniform(seed, t, k, kTipV1),
                                        style.clump * counterUniform(seed, t, k, kTipV2), style.strayHairs);
      const size_t p0 = firstPoint[t] - pointBase + uint64_t(k) * n;
      local.blend.blend(root, tip, &coupe.points[p0], &coupe.tangents[p0]);
      coupe.firstPoint[s] = static_cast<uint32_t>(p0);
      coupe.strandId[s] = static_cast<uint32_t>(uint64_t(k) * triangleCount + t);
      coupe.rootTriangle[s] = static_cast<uint32_t>(t);
      coupe.rootBary[s] = glm::vec3(root);
      coupe.guideIds[s] = tri;
      coupe.guideWeights[s] = glm::vec3(root);
      if (!wick.uvs.empty())
        coupe.rootUv[s] =
            glm::vec2(root.x * glm::dvec2(wick.uvs[tri.x]) + root.y * glm::dvec2(wick.uvs[tri.y]) +
                      root.z * glm::dvec2(wick.uvs[tri.z]));
    }
    if (options.progress) options.progress->advance();
  });
  if (options.progress) options.progress->finish();

  coupe.defaultThickness = guides.defaultThickness;
  coupe.defaultTransparency = guides.defaultTransparency;
  coupe.defaultColor = guides.defaultColor;
  coupe.provenance = madeByHairgen("interpolate", seed, options.configDigest);
  coupe.provenance.shard = options.shard;
  coupe.provenance.frame = guides.provenance.frame;  // a frame's coupe is that frame's
  coupe.provenance.time = guides.provenance.time;
}

}  // namespace hairgen
