// The interpolate stage: roots on the wick, counts from area × density, the thesis' tip weights and
// stray hairs, stable nested identity, thread-count independence, guides of unequal vertex counts.
#include <gtest/gtest.h>

#include <cstring>
#include <map>
#include <random>

#include <tbb/global_control.h>

#include "libcore/config/setup.h"
#include "libcore/io/obj_io.h"
#include "libcore/util/error.h"
#include "libcore/util/random.h"
#include "stages/grow.h"
#include "stages/interpolate.h"
#include "tests/test_util.h"

namespace hairgen {
namespace {

// Coupe 2 grown once (its guides are the cheapest to grow) and shared by the tests.
struct Grown : test::Job {
  Strands guides;
  Grown() : test::Job(test::loadJob("thesis/coupe2/setup.txt", SetupUse::kInterpolate)) {
    guides = grow(wick, config.hairstyle, config.collision, {}).guides;
  }
};
const Grown& grown() {
  static const Grown g;
  return g;
}

Strands coupeAt(double density, uint64_t seed = 7) {
  Hairstyle h = grown().config.hairstyle;
  h.hairDensity = density;
  h.seed = seed;
  return interpolate(grown().wick, grown().guides, h, grown().config.collision, {});
}

TEST(Interpolate, EveryRootLiesOnItsTriangle) {
  Strands coupe = coupeAt(100);
  const Mesh& wick = grown().wick;
  ASSERT_GT(coupe.strandCount(), 10000u);
  for (size_t s = 0; s < coupe.strandCount(); ++s) {
    const glm::uvec3 t = wick.triangles[coupe.rootTriangle[s]];
    glm::dvec3 a(wick.positions[t.x]), b(wick.positions[t.y]), c(wick.positions[t.z]);
    glm::dvec3 n = glm::normalize(glm::cross(b - a, c - a));
    glm::dvec3 root(coupe.points[coupe.firstPoint[s]]);
    ASSERT_LT(std::abs(glm::dot(root - a, n)), 1e-6) << "strand " << s;
    glm::dvec3 w(coupe.rootBary[s]);
    ASSERT_GE(std::min({w.x, w.y, w.z}), 0.0);
    ASSERT_LE(std::max({w.x, w.y, w.z}), 1.0);
    ASSERT_NEAR(w.x + w.y + w.z, 1.0, 1e-6);
    ASSERT_LT(glm::length(root - (w.x * a + w.y * b + w.z * c)), 1e-6) << "strand " << s;
  }
}

TEST(Interpolate, OneCornerWeightsReproduceThatGuideExactly) {
  const Strands& guides = grown().guides;
  const glm::uvec3 tri = grown().wick.triangles[100];
  GuideSpan g[3];
  for (int c = 0; c < 3; ++c)
    g[c] = {&guides.points[guides.firstPoint[tri[c]]], &guides.tangents[guides.firstPoint[tri[c]]]};
  const uint32_t n = guides.pointsOf(tri.x);
  std::vector<glm::vec3> p(n), t(n);
  TriangleBlend blend;
  blend.prepare(g, n, strayCentre(grown().config.collision));
  for (int c = 0; c < 3; ++c) {
    glm::dvec3 corner(0.0);
    corner[c] = 1.0;
    blend.blend(corner, corner, p.data(), t.data());
    for (uint32_t i = 0; i < n; ++i) {
      ASSERT_EQ(p[i], g[c].points[i]) << "corner " << c << " vertex " << i;
      ASSERT_EQ(t[i], g[c].tangents[i]) << "corner " << c << " vertex " << i;
    }
  }
}

// The blend runs across vertices in vector registers; its bits must stay those of the formula taken one
// vertex at a time in double (caches are compared byte for byte): w = root + (tip − root)·f, p = centre
// + Σ w_c (g_c − centre), t = Σ w_c t_c / |t|. A fused multiply-add or a reordered sum fails this.
TEST(Interpolate, BlendKeepsTheBitsOfOneVertexAtATime) {
  const Strands& guides = grown().guides;
  const glm::uvec3 tri = grown().wick.triangles[200];
  GuideSpan g[3];
  for (int c = 0; c < 3; ++c)
    g[c] = {&guides.points[guides.firstPoint[tri[c]]], &guides.tangents[guides.firstPoint[tri[c]]]};
  const uint32_t n = guides.pointsOf(tri.x);
  const glm::dvec3 centre = strayCentre(grown().config.collision);
  TriangleBlend blend;
  blend.prepare(g, n, centre);
  std::vector<glm::vec3> p(n), t(n);
  for (uint64_t k = 0; k < 50; ++k) {
    const glm::dvec3 root = rootWeights(counterUniform(3, 0, k, 0), counterUniform(3, 0, k, 1));
    const glm::dvec3 tip =
        tipWeights(root, 0.4 * counterUniform(3, 0, k, 2), 0.4 * counterUniform(3, 0, k, 3), k % 2 == 0);
    blend.blend(root, tip, p.data(), t.data());
    for (uint32_t i = 0; i < n; ++i) {
      const glm::dvec3 w = root + (tip - root) * (double(i) / double(n - 1));
      glm::dvec3 point = centre, tangent(0.0);
      for (int c = 0; c < 3; ++c) {
        point += w[c] * (glm::dvec3(g[c].points[i]) - centre);
        tangent += w[c] * glm::dvec3(g[c].tangents[i]);
      }
      const glm::vec3 expectPoint(point), expectTangent(tangent / glm::length(tangent));
      ASSERT_EQ(std::memcmp(&p[i], &expectPoint, sizeof p[i]), 0) << "strand " << k << " vertex " << i;
      ASSERT_EQ(std::memcmp(&t[i], &expectTangent, sizeof t[i]), 0) << "strand " << k << " vertex " << i;
    }
  }
}

TEST(Interpolate, CountsFollowAreaTimesDensity) {
  const double density = 37.3;
  Strands coupe = coupeAt(density);
  const Mesh& wick = grown().wick;
  std::vector<uint32_t> perTriangle(wick.triangles.size(), 0);
  for (uint32_t t : coupe.rootTriangle) ++perTriangle[t];
  double expected = 0.0;
  for (size_t t = 0; t < wick.triangles.size(); ++t) {
    double n = triangleArea(wick, t) * 1e4 * density;
    expected += n;
    ASSERT_TRUE(perTriangle[t] == std::floor(n) || perTriangle[t] == std::floor(n) + 1) << "triangle " << t;
  }
  EXPECT_NEAR(double(coupe.strandCount()), expected, 0.01 * expected);
  // For one triangle's uniform the count never falls as the density rises.
  for (double u : {0.0, 0.3, 0.999}) {
    uint32_t last = 0;
    for (double d = 0.0; d < 50.0; d += 0.01) {
      uint32_t n = strandsInTriangle(0.37, d, u);
      ASSERT_GE(n, last) << "density " << d;
      last = n;
    }
  }
}

TEST(Interpolate, StrayHairsFollowTheThesisTable) {
  // Table 4 of §4.1.4.4: for each ordering of the root weights, which of v1, v2, v3 each corner gets.
  // Orderings are keyed by the corners from largest to smallest root weight.
  const std::map<std::string, std::string> table = {{"ABC", "321"}, {"ACB", "311"}, {"BCA", "132"},
                                                    {"BAC", "131"}, {"CAB", "213"}, {"CBA", "113"}};
  std::map<std::string, int> seen;
  int notOne = 0, trials = 20000;
  for (int k = 0; k < trials; ++k) {
    glm::dvec3 root = rootWeights(counterUniform(1, 0, k, 0), counterUniform(1, 0, k, 1));
    double v1 = 0.25 * counterUniform(1, 0, k, 2), v2 = 0.25 * counterUniform(1, 0, k, 3);
    std::string order = "ABC";
    std::sort(order.begin(), order.end(), [&](char a, char b) { return root[a - 'A'] > root[b - 'A']; });
    glm::dvec3 tip = tipWeights(root, v1, v2, true);
    const double v[4] = {0.0, v1, v2, 1.0 - (v1 + v2)};
    const std::string& expect = table.at(order);
    for (int c = 0; c < 3; ++c) ASSERT_EQ(tip[c], v[expect[c] - '0']) << order << " corner " << c;
    ++seen[order];
    notOne += std::abs(tip.x + tip.y + tip.z - 1.0) > 1e-12;
    glm::dvec3 fixed = tipWeights(root, v1, v2, false);
    ASSERT_NEAR(fixed.x + fixed.y + fixed.z, 1.0, 1e-12);
    int nearest = order[0] - 'A';
    ASSERT_EQ(fixed[nearest], 1.0 - (v1 + v2));
  }
  EXPECT_EQ(seen.size(), 6u);
  for (const auto& [order, n] : seen) EXPECT_NEAR(n, trials / 6, trials / 30) << order;
  EXPECT_NEAR(notOne, trials / 2, trials / 20);
}

TEST(Interpolate, RootWeightsAreUniformOverTheTriangle) {
  // Each of the four sub-triangles cut by the midpoints gets a quarter of the roots.
  int counts[4] = {0, 0, 0, 0}, trials = 40000;
  for (int k = 0; k < trials; ++k) {
    glm::dvec3 w = rootWeights(counterUniform(3, 0, k, 0), counterUniform(3, 0, k, 1));
    counts[w.x > 0.5 ? 0 : w.y > 0.5 ? 1 : w.z > 0.5 ? 2 : 3]++;
  }
  for (int c : counts) EXPECT_NEAR(c, trials / 4, trials / 50);
}

TEST(Interpolate, DoublingTheDensityKeepsEveryStrandByteForByte) {
  Strands low = coupeAt(40), high = coupeAt(80);
  EXPECT_GT(high.strandCount(), low.strandCount() * 19 / 10);
  std::map<uint32_t, size_t> byId;
  for (size_t s = 0; s < high.strandCount(); ++s) byId[high.strandId[s]] = s;
  for (size_t s = 0; s < low.strandCount(); ++s) {
    auto it = byId.find(low.strandId[s]);
    ASSERT_NE(it, byId.end()) << "strand id " << low.strandId[s] << " is gone";
    size_t h = it->second;
    ASSERT_EQ(low.pointsOf(s), high.pointsOf(h));
    ASSERT_EQ(0, std::memcmp(&low.points[low.firstPoint[s]], &high.points[high.firstPoint[h]],
                             low.pointsOf(s) * sizeof(glm::vec3)));
    ASSERT_EQ(0, std::memcmp(&low.tangents[low.firstPoint[s]], &high.tangents[high.firstPoint[h]],
                             low.pointsOf(s) * sizeof(glm::vec3)));
    ASSERT_EQ(low.rootBary[s], high.rootBary[h]);
  }
}

TEST(Interpolate, OutputIsIdenticalForAnyThreadCount) {
  Strands one;
  {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
    one = coupeAt(60);
  }
  EXPECT_TRUE(one == coupeAt(60));
  EXPECT_FALSE(one == coupeAt(60, 8)) << "the seed changes nothing";
}

// A sequence interpolates every frame into one Strands: whatever it held, what comes out is the fresh
// coupe, and a coupe of the same size is written in place.
TEST(Interpolate, IntoAUsedCoupeGivesTheFreshCoupeInItsStorage) {
  Strands used = coupeAt(80);
  used.normals.assign(used.pointCount(), glm::vec3(0, 1, 0));
  used.colors.assign(used.pointCount(), glm::vec3(0.5f));
  used.thickness.assign(used.pointCount(), 1e-4f);
  used.transparency.assign(used.pointCount(), 0.5f);
  used.simulationState.assign(10, 1.0);
  used.defaultThickness = 1e-3f;
  used.provenance.stage = "shade";
  Hairstyle h = grown().config.hairstyle;
  h.hairDensity = 40;
  h.seed = 7;
  interpolateInto(grown().wick, grown().guides, h, grown().config.collision, {}, used);
  EXPECT_TRUE(used == coupeAt(40));
  const glm::vec3* storage = used.points.data();
  h.seed = 8;
  interpolateInto(grown().wick, grown().guides, h, grown().config.collision, {}, used);
  EXPECT_TRUE(used == coupeAt(40, 8));
  EXPECT_EQ(used.points.data(), storage) << "the same strands reallocated their points";
}

TEST(Interpolate, GuidesOfDifferentVertexCountsBlendByArcLength) {
  // Three straight guides 10 cm up from the corners, with 21, 11 and 6 vertices.
  Mesh wick;
  wick.positions = {{0, 0, 0}, {0.01f, 0, 0}, {0, 0, 0.01f}};
  wick.normals = {{0, 1, 0}, {0, 1, 0}, {0, 1, 0}};
  wick.triangles = {{0, 1, 2}};
  Strands guides;
  for (int c = 0; c < 3; ++c) {
    int n = c == 0 ? 21 : c == 1 ? 11 : 6;
    std::vector<glm::vec3> p;
    for (int i = 0; i < n; ++i) p.push_back(wick.positions[c] + glm::vec3(0, 0.1f * i / (n - 1), 0));
    guides.addStrand(p);
  }
  Hairstyle h;
  h.hairDensity = 2000;  // 0.5 cm² → 1000 strands
  h.strayHairs = false;
  Strands coupe = interpolate(wick, guides, h, Collision{}, {});
  ASSERT_GT(coupe.strandCount(), 900u);
  for (size_t s = 0; s < coupe.strandCount(); ++s) {
    ASSERT_EQ(coupe.pointsOf(s), 21u);
    for (uint32_t i = 0; i < 21; ++i) {
      const glm::vec3& p = coupe.points[coupe.firstPoint[s] + i];
      ASSERT_NEAR(p.y, 0.1 * i / 20.0, 1e-6) << "strand " << s << " vertex " << i;
      ASSERT_NEAR(coupe.tangents[coupe.firstPoint[s] + i].y, 1.0, 1e-6);
    }
  }
}

TEST(Interpolate, GuidesThatDoNotFitTheWickAreAnInputError) {
  Strands fewer = grown().guides;
  fewer.points.resize(fewer.firstPoint[10]);
  fewer.tangents.resize(fewer.firstPoint[10]);
  fewer.firstPoint.resize(11);
  fewer.strandId.resize(10);
  EXPECT_THROW(interpolate(grown().wick, fewer, grown().config.hairstyle, {}, {"", "g.hair"}), InputError);
  Strands moved = grown().guides;
  for (uint32_t p = moved.firstPoint[3]; p < moved.firstPoint[4]; ++p) moved.points[p].x += 0.01f;
  try {
    interpolate(grown().wick, moved, grown().config.hairstyle, {}, {"", "g.hair"});
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("guide 3 starts 10"), std::string::npos) << e.what();
  }
}

TEST(Interpolate, StrayHairsScaleAboutTheHeadShape) {
  Collision c;
  c.shapes.resize(3);
  c.shapes[0].kind = ShapeKind::kSphere;
  c.shapes[1].kind = c.shapes[2].kind = ShapeKind::kEllipsoid;
  c.shapes[2].fitted = true;
  for (size_t i = 0; i < 3; ++i) c.shapes[i].centre = glm::dvec3(double(i + 1), 0.0, 0.0);
  EXPECT_EQ(strayCentre(c), headShape(c)->centre);
  EXPECT_EQ(strayCentre(Collision{}), glm::dvec3(0.0));
}

}  // namespace
}  // namespace hairgen
