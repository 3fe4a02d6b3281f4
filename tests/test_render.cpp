// The renderer on llvmpipe (or a GPU): each shading model against the CPU formula, deep-opacity shadows
// between strands and onto the head, the background's AOVs, what supersampling changes, a Setup's
// custom shaders, and the stage's framing and conforming of foreign hair.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cstring>
#include <limits>

#include <tbb/global_control.h>

#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfStandardAttributes.h>
#include <glm/gtc/matrix_transform.hpp>

#include "libcore/io/exr_io.h"
#include "libcore/io/obj_io.h"
#include "libcore/render/camera_fragments.h"
#include "libcore/render/custom_shaders.h"
#include "libcore/render/gl_context.h"
#include "libcore/render/gl_resources.h"
#include "libcore/render/light_maps.h"
#include "libcore/render/line_decimation.h"
#include "libcore/render/shader_interface.h"
#include "libcore/render/shading.h"
#include "libcore/util/file_util.h"
#include "stages/grow.h"
#include "stages/interpolate.h"
#include "stages/render.h"
#include "tests/test_util.h"

namespace hairgen {
namespace {

// The shading pass draws chords: every point dropped lies within the tolerance of the chord that
// replaces it, ends are kept, a chord spans at most kMostSegmentsPerChord segments, and what bends more
// than the tolerance keeps its points.
TEST(LineDecimation, ChordsStayWithinToleranceOfEveryPointTheyDrop) {
  Strands s;
  std::vector<glm::vec3> straight, zigzag, arc, single = {glm::vec3(0.0f)};
  for (int j = 0; j < 64; ++j) {
    straight.push_back(glm::vec3(0.0f, -0.003f * j, 0.0f));
    zigzag.push_back(glm::vec3(j % 2 ? 0.001f : 0.0f, -0.003f * j, 0.01f));
    const double a = 0.05 * j;  // a 2 cm radius arc: 3 mm segments bend 0.06 mm off their chords of two
    arc.push_back(glm::vec3(float(0.02 * std::cos(a)), float(0.02 * std::sin(a)), 0.02f));
  }
  std::vector<glm::vec3> pair = {glm::vec3(0.0f), glm::vec3(0.0f, -0.01f, 0.0f)};
  for (const auto* points : {&straight, &single, &zigzag, &arc, &pair}) s.addStrand(*points);
  const double tolerance = 1e-4;
  auto stripsOf = [](const std::vector<uint32_t>& indices) {
    std::vector<std::vector<uint32_t>> strips(1);
    for (uint32_t i : indices) {
      if (i == kRestartIndex)
        strips.emplace_back();
      else
        strips.back().push_back(i);
    }
    EXPECT_TRUE(strips.back().empty()) << "every strip ends with a restart";
    strips.pop_back();
    return strips;
  };
  const std::vector<std::vector<uint32_t>> strips = stripsOf(decimatedLineStrips(s, tolerance));
  ASSERT_EQ(strips.size(), 4u);  // the one-point strand draws nothing
  EXPECT_EQ(strips[3], (std::vector<uint32_t>{s.firstPoint[4], s.firstPoint[4] + 1}))
      << "a pair is one chord";
  // The straight strand: one chord every kMostSegmentsPerChord segments.
  EXPECT_EQ(strips[0].size(), 63 / kMostSegmentsPerChord + 2);
  EXPECT_EQ(strips[1].size(), 64u) << "a zigzag of 1 mm against 0.1 mm keeps every point";
  EXPECT_GT(strips[2].size(), 64u / kMostSegmentsPerChord);
  EXPECT_LT(strips[2].size(), 64u);
  const size_t strandOf[4] = {0, 2, 3, 4};
  for (size_t k = 0; k < strips.size(); ++k) {
    const std::vector<uint32_t>& strip = strips[k];
    const size_t strand = strandOf[k];
    EXPECT_EQ(strip.front(), s.firstPoint[strand]);
    EXPECT_EQ(strip.back(), s.firstPoint[strand] + s.pointsOf(strand) - 1);
    for (size_t c = 0; c + 1 < strip.size(); ++c) {
      ASSERT_LT(strip[c], strip[c + 1]);
      EXPECT_LE(strip[c + 1] - strip[c], kMostSegmentsPerChord);
      const glm::dvec3 a(s.points[strip[c]]), b(s.points[strip[c + 1]]);
      for (uint32_t p = strip[c] + 1; p < strip[c + 1]; ++p) {
        const glm::dvec3 q(s.points[p]);
        const double t = glm::clamp(glm::dot(q - a, b - a) / glm::dot(b - a, b - a), 0.0, 1.0);
        EXPECT_LE(glm::length(q - (a + t * (b - a))), tolerance) << "point " << p;
      }
    }
  }
  // Tolerance 0 keeps every point of the bent strands.
  const std::vector<std::vector<uint32_t>> exact = stripsOf(decimatedLineStrips(s, 0.0));
  ASSERT_EQ(exact.size(), 4u);
  EXPECT_EQ(exact[1].size(), 64u);
  EXPECT_EQ(exact[2].size(), 64u);
}

// In a drawing order, the strips come in that order, each the strip its strand has alone; frontToBack
// gives every strand of two points or more once, the nearest to the eye first.
TEST(LineDecimation, StripsFollowTheDrawingOrderFrontToBack) {
  Strands s;
  for (int k = 0; k < 6; ++k) {  // strand k at depth 1 + (k * 5) % 6 metres in front of an eye at the origin
    const float z = -1.0f - float((k * 5) % 6);
    std::vector<glm::vec3> points;
    for (int j = 0; j < (k == 3 ? 1 : 5); ++j) points.push_back(glm::vec3(0.01f * j, 0.002f * j * j, z));
    s.addStrand(points);
  }
  const std::vector<uint32_t> order =
      frontToBack(s, glm::dmat4(1.0));  // the eye at the origin, looking down −z
  ASSERT_EQ(order.size(), 5u) << "the one-point strand is not drawn";
  EXPECT_EQ(order.front(), 0u);
  EXPECT_EQ(order.back(), 1u) << "the farthest, drawn last";
  for (size_t i = 0; i + 1 < order.size(); ++i)
    EXPECT_GT(s.points[s.firstPoint[order[i]]].z, s.points[s.firstPoint[order[i + 1]]].z) << "nearest first";
  const std::vector<uint32_t> ordered = decimatedLineStrips(s, 1e-4, order);
  std::vector<uint32_t> expected;
  for (uint32_t strand : order) {
    Strands alone;
    alone.addStrand(std::vector<glm::vec3>(s.points.begin() + s.firstPoint[strand],
                                           s.points.begin() + s.firstPoint[strand] + s.pointsOf(strand)));
    for (uint32_t i : decimatedLineStrips(alone, 1e-4))
      expected.push_back(i == kRestartIndex ? i : i + s.firstPoint[strand]);
  }
  EXPECT_EQ(ordered, expected);
}

// The light's maps (light_maps.h) on an orthographic view whose window coordinates are the world's x
// and y (texels) and whose depth is −z; focalPx 1, so a strand at depth 1 m is its width in texels.
View texelView(int size) {
  View v;
  v.width = v.height = size;
  v.proj = glm::ortho(0.0, double(size), 0.0, double(size), -100.0, 100.0);
  return v;
}

Strands strip(std::initializer_list<glm::vec3> points) {
  Strands s;
  s.addStrand(std::vector<glm::vec3>(points));
  return s;
}

constexpr glm::dvec4 kLayers{0.002, 0.006, 0.015, 0.04};

// All the coverage the maps hold, in texels (the last layer has every sample's).
double totalCoverage(const HairLightMaps& maps) {
  double sum = 0.0;
  for (const glm::uvec4& l : maps.layers) sum += double(l.w);
  return sum / double(kCoverageOne);
}

// A strand's coverage is its ribbon's area, width × length in texels, at any angle and width, whether
// thinner or wider than a texel; a strip's shared point is counted once (two segments cover what one
// straight segment does).
TEST(HairLightMaps, ASegmentCoversItsWidthTimesItsLength) {
  for (const double width : {0.1, 0.3, 1.0, 3.0})
    for (const double angle : {0.0, 0.3, 0.785, 1.2, 1.5708}) {
      const glm::dvec2 d(std::cos(angle), std::sin(angle));
      const glm::dvec2 a = glm::dvec2(64.3, 61.7) - 20.0 * d, m = a + 17.0 * d, b = a + 40.0 * d;
      const Strands one = strip({{a.x, a.y, -1.0f}, {b.x, b.y, -1.0f}});
      const Strands two = strip({{a.x, a.y, -1.0f}, {m.x, m.y, -1.0f}, {b.x, b.y, -1.0f}});
      const double got = totalCoverage(rasteriseLightMaps(one, texelView(128), width, kLayers));
      EXPECT_NEAR(got, width * 40.0, 0.01 * width * 40.0) << width << " texels at " << angle;
      const double split = totalCoverage(rasteriseLightMaps(two, texelView(128), width, kLayers));
      EXPECT_NEAR(split, got, 0.01 * got) << width << " texels at " << angle;
    }
}

// A strand thousands of texels wide drawn for one band of rows: the fragments in those rows are the
// same bits as when every row is wanted (the rows passed over still count toward the last texel's
// remainder), with either filter, and the band costs its rows, not the strand's width.
template <raster::Across across>
void expectABandsRowsAsAllRows(raster::Vertex a, raster::Vertex b) {
  struct Fragment {
    int64_t i, j;
    int32_t depth;
    uint32_t coverage;
    int64_t twice;
    bool operator==(const Fragment&) const = default;
  };
  auto draw = [&](int64_t rowLo, int64_t rowHi, size_t& calls) {
    std::vector<Fragment> in;
    calls = 0;
    raster::rasteriseSegment<across>(a, b, rowLo, rowHi,
                                     [&](int64_t i, int64_t j, int32_t depth, uint32_t c, raster::Piece p) {
                                       ++calls;
                                       if (j >= rowLo && j < rowHi) in.push_back({i, j, depth, c, p.twice});
                                     });
    return in;
  };
  size_t allCalls = 0, bandCalls = 0;
  const std::vector<Fragment> all = draw(-100000, 100000, allCalls);
  const int64_t columns = std::abs(int64_t(b.x) - a.x) / kSubTexel + 2;
  for (const int64_t rowLo : {int64_t(0), int64_t(1984), int64_t(2016), int64_t(3520), int64_t(5000)}) {
    const int64_t rowHi = rowLo + raster::kBandRows;
    std::vector<Fragment> want;
    for (const Fragment& f : all)
      if (f.j >= rowLo && f.j < rowHi) want.push_back(f);
    EXPECT_TRUE(draw(rowLo, rowHi, bandCalls) == want) << "rows from " << rowLo;
    EXPECT_LE(bandCalls, size_t(columns) * (raster::kBandRows + 6)) << "rows from " << rowLo;
  }
  EXPECT_GT(allCalls, size_t(columns) * 2000);
}

TEST(HairRaster, ABandOfAWideStrandIsTheSameBitsAndCostsItsRows) {
  // 3000 and 4096 texels wide (the widest drawn), slanting up and down, along x.
  for (const int32_t width : {3000, 4096})
    for (const int32_t rise : {25470, -31337, 0}) {
      const raster::Vertex a{2637, 2000 * kSubTexel + 179, 1000000, width * kWidthUnit};
      const raster::Vertex b{300 * kSubTexel + 150, 2000 * kSubTexel + 179 + rise, 1003000,
                             width * kWidthUnit};
      expectABandsRowsAsAllRows<raster::Across::kBox>(a, b);
      expectABandsRowsAsAllRows<raster::Across::kTent>(a, b);
    }
}

// The rasteriser's quotients by a reciprocal are integer division's, rounded toward −∞: at the signs'
// and the remainders' edges, for the divisors and numerators a segment has (its length along the major
// axis, up to 2^27 in 1/kSubTexel; products up to 2^63), and past 2^50, where the double's estimate is
// off by more than one and the exact division is taken instead.
TEST(HairRaster, ADividersQuotientsAreIntegerDivisions) {
  uint64_t state = 0x9e3779b97f4a7c15ull;
  auto next = [&] {
    state ^= state << 13, state ^= state >> 7, state ^= state << 17;
    return state;
  };
  std::vector<int64_t> divisors = {1, 2, 3, 255, 256, 512, 513, (int64_t(1) << 27) - 1, int64_t(1) << 28};
  while (divisors.size() < 200) divisors.push_back(int64_t(1 + next() % (uint64_t(1) << (1 + next() % 34))));
  size_t checked = 0;
  for (const int64_t d : divisors) {
    const raster::Divider divider(d);
    std::vector<int64_t> numerators = {0, 1, -1, d - 1, d, d + 1, -d, -d - 1, -d + 1, 3 * d, -3 * d};
    for (int k = 0; k < 400; ++k) {
      const int bits = int(next() % 63);
      const int64_t magnitude = int64_t(next() >> (63 - bits));  // below 2^(bits + 1)
      const int64_t n = next() % 2 ? magnitude : -magnitude;
      numerators.insert(numerators.end(), {n, n - n % d, n - n % d - 1, n - n % d + 1});
    }
    numerators.push_back(std::numeric_limits<int64_t>::max() - d);  // a quotient near 2^63 / d
    for (const int64_t n : numerators) {
      ASSERT_EQ(divider.floor(n), raster::floorDiv(n, d)) << n << " / " << d;
      ++checked;
    }
    uint64_t rest = 0;
    const uint64_t n = next() >> 2;
    ASSERT_EQ(divider.floor(n, rest), n / uint64_t(d));
    EXPECT_EQ(rest, n % uint64_t(d));
  }
  EXPECT_GT(checked, size_t(200 * 1600));
}

// Two strands over the same texels, the second 4 mm behind the first: with layers of 2, 6, 15 and 40 mm
// it adds to the second layer and those behind, not the first; where the hair begins is the first's
// depth. (A strand's width in texels is its width over its depth: 0.5 texel at 1 m, 0.498 at 1.004 m.)
TEST(HairLightMaps, OpacityFallsInTheLayersBehindWhereTheHairBegins) {
  Strands s = strip({{2.0f, 4.5f, -1.0f}, {13.0f, 4.5f, -1.0f}});
  s.addStrand({{2.0f, 4.5f, -1.004f}, {13.0f, 4.5f, -1.004f}});
  const HairLightMaps maps = rasteriseLightMaps(s, texelView(16), 0.5, kLayers);
  const std::vector<float> start = maps.startMetres(1e10f);
  const std::vector<glm::vec4> opacity = maps.opacity(0.8);
  // A strand w texels wide along a texel row's middle: the texel's tent holds w − w²/4 of its
  // cross-section (the rest falls to the rows either side), opacity 0.8.
  auto held = [](double w) { return float(0.8 * (w - w * w / 4.0)); };
  for (int x = 4; x <= 10; ++x) {
    const size_t t = 4 * 16 + x;
    EXPECT_EQ(start[t], 1.0f) << x;
    // (The cross-section is kept to 1/256 texel.)
    EXPECT_NEAR(opacity[t].x, held(0.5), 5e-4f) << x;
    EXPECT_NEAR(opacity[t].y, held(0.5) + held(0.5 / 1.004), 5e-4f) << x;
    EXPECT_EQ(opacity[t].y, opacity[t].z);
    EXPECT_EQ(opacity[t].z, opacity[t].w);
  }
  // Written over the integers' storage for an upload, the same floats.
  HairLightMaps spent = maps;
  const void* startInPlace = spent.startMetresInPlace(1e10f);
  const void* opacityInPlace = spent.opacityInPlace(0.8);
  EXPECT_EQ(std::memcmp(startInPlace, start.data(), start.size() * sizeof(float)), 0);
  EXPECT_EQ(std::memcmp(opacityInPlace, opacity.data(), opacity.size() * sizeof(glm::vec4)), 0);
  EXPECT_EQ(start[0], 1e10f) << "the test has texels without hair";
  // Their integers are gone: asked for again, they are refused.
  EXPECT_THROW(spent.startMetresInPlace(1e10f), std::logic_error);
  EXPECT_THROW((void)spent.opacity(0.8), std::logic_error);
}

// 3,000 strands of 12 points crossing in every direction over a 256-texel view, at 7 depths.
Strands crossingEveryWay() {
  Strands s;
  for (int i = 0; i < 3000; ++i) {
    const float a = 0.37f * float(i), r = 40.0f + 30.0f * std::sin(0.11f * float(i));
    std::vector<glm::vec3> points;
    for (int k = 0; k < 12; ++k) {
      const float t = float(k) / 11.0f;
      points.push_back({128.0f + r * std::cos(a + 2.0f * t), 128.0f + r * std::sin(a * 1.3f + 3.0f * t),
                        -1.0f - 0.01f * float(i % 7)});
    }
    s.addStrand(points);
  }
  return s;
}

// Bands sorted straight from the points are those of the projection's list of segments, whatever
// storage is reused: strands crossing every way, some with points behind the view (their segments are
// not drawn) and some reaching past its edges, and strands of one point, which have no segment.
TEST(HairRaster, BandsFromThePointsAreTheProjectionsBands) {
  Strands s = crossingEveryWay();
  s.addStrand({{10.0f, 10.0f, -1.0f}, {20.0f, 30.0f, 1.0f}, {30.0f, 40.0f, -1.0f}, {40.0f, 45.0f, -1.0f}});
  s.addStrand({{-40.0f, 100.0f, -1.0f}, {300.0f, 120.0f, -1.0f}});
  s.addStrand({{50.0f, 50.0f, -1.0f}});
  s.addStrand({{100.0f, -30.0f, -1.0f}, {110.0f, 290.0f, -1.0f}});
  auto same = [](const raster::Bands& a, const raster::Bands& b) {
    return a.width == b.width && a.height == b.height && a.count == b.count && a.bandFirst == b.bandFirst &&
           a.bandSegments == b.bandSegments &&
           std::equal(a.vertices.begin(), a.vertices.end(), b.vertices.begin(), b.vertices.end(),
                      [](const raster::Vertex& u, const raster::Vertex& v) {
                        return u.x == v.x && u.y == v.y && u.depth == v.depth && u.width == v.width;
                      });
  };
  for (const int size : {256, 100}) {
    const View view = texelView(size);
    const raster::Bands listed = raster::intoBands(raster::project(s, view, 0.7));
    EXPECT_GT(listed.bandSegments.size(), size_t(size) * 100) << size;
    EXPECT_TRUE(same(raster::projectIntoBands(s, view, 0.7), listed)) << size;
    // Reusing a larger projection's storage, and a smaller one's.
    EXPECT_TRUE(same(raster::projectIntoBands(s, view, 0.7, raster::projectIntoBands(s, texelView(512), 3.0)),
                     listed))
        << size;
    EXPECT_TRUE(same(raster::projectIntoBands(
                         s, view, 0.7, raster::projectIntoBands(strip({{1, 1, -1}, {5, 5, -1}}), view, 0.7)),
                     listed))
        << size;
  }
}

// Many strands crossing in every direction at equal depths: integer minima and sums, the same bits
// on one thread as on all, and on a second run.
TEST(HairLightMaps, TheMapsAreTheSameBitsOnOneThreadAsOnAll) {
  const Strands s = crossingEveryWay();
  auto maps = [&] { return rasteriseLightMaps(s, texelView(256), 0.7, kLayers); };
  const HairLightMaps all = maps(), again = maps();
  tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
  const HairLightMaps single = maps();
  EXPECT_TRUE(all.start == single.start && all.start == again.start);
  EXPECT_TRUE(all.layers == single.layers && all.layers == again.layers);
}

// The maps are their definition's, every fragment counted, however near or far each arrives after those
// before it: the rasteriser keeps only the fragments near enough to where its texel's hair begins so
// far to fall in the first three layers. Strands at seven depths 10 mm apart (layers end 2, 8 and 23 mm
// behind where the hair begins), sloping 30 mm along their length, in an order mixing near and far.
TEST(HairLightMaps, TheLayersAreEveryFragmentsSumsWhateverOrderTheyArriveIn) {
  Strands s = crossingEveryWay();
  for (size_t p = 0; p < s.points.size(); ++p) s.points[p].z -= 0.03f * float(p % 12) / 11.0f;
  const View view = texelView(256);
  const HairLightMaps maps = rasteriseLightMaps(s, view, 0.7, kLayers);
  const raster::Bands bands = raster::projectIntoBands(s, view, 0.7);
  std::vector<int32_t> start(maps.start.size(), INT32_MAX);
  std::vector<std::array<int64_t, 3>> fragments;  // texel, depth, coverage
  for (int b = 0; b < bands.count; ++b)
    bands.eachFragment<raster::Across::kTent>(
        b, [&](size_t t, int32_t depth, uint32_t coverage, uint32_t, raster::Piece) {
          start[t] = std::min(start[t], depth);
          fragments.push_back({int64_t(t), depth, coverage});
        });
  const std::array<int64_t, 3> ends = layerEnds(kLayers);
  std::vector<glm::uvec4> layers(maps.layers.size(), glm::uvec4(0));
  size_t beyond = 0;
  for (const auto& [t, depth, coverage] : fragments) {
    const int64_t behind = depth - start[size_t(t)];
    beyond += behind >= ends[2];
    for (int k = 0; k < 3; ++k)
      if (behind < ends[k]) raster::addSaturating(layers[size_t(t)][k], uint32_t(coverage));
    raster::addSaturating(layers[size_t(t)][3], uint32_t(coverage));
  }
  EXPECT_GT(beyond, fragments.size() / 4) << "the test has fragments behind the first three layers";
  EXPECT_TRUE(maps.start == start);
  EXPECT_TRUE(maps.layers == layers);
}

// A strand moved by a hundredth of a texel moves a hundredth of its coverage: the maps are continuous
// in the hair's position (each sample is splatted bilinearly), so shadows do not jump.
TEST(HairLightMaps, AStrandMovedAHundredthOfATexelChangesTheMapsByAboutAHundredth) {
  for (const double angle : {0.0, 0.4, 1.5708}) {
    const glm::dvec2 d(std::cos(angle), std::sin(angle)), n(-d.y, d.x);
    auto mapsAt = [&](double shift) {
      const glm::dvec2 a = glm::dvec2(32.0, 32.0) - 15.0 * d + shift * n, b = a + 30.0 * d;
      return rasteriseLightMaps(strip({{a.x, a.y, -1.0f}, {b.x, b.y, -1.0f}}), texelView(64), 0.3, kLayers);
    };
    const HairLightMaps before = mapsAt(0.0), after = mapsAt(0.01);
    double moved = 0.0, largest = 0.0;
    for (size_t t = 0; t < before.layers.size(); ++t) {
      const double change = std::abs(double(after.layers[t].w) - double(before.layers[t].w)) / kCoverageOne;
      moved += change;
      largest = std::max(largest, change);
    }
    const double total = totalCoverage(before);
    // Moving across by δ moves about 2δ of the coverage (out of one texel row, into the next).
    EXPECT_LT(moved, 0.03 * total) << angle;
    EXPECT_LT(largest, 0.03 * 0.3) << angle;
  }
}

// The camera's fragments (camera_fragments.h) on the texel view: pixel (x, y) is the world's x and y,
// depth −z.

// A fragment's coverage (kCoverageOne a pixel) and the sum of a pixel's fragments' and tail's.
double coverageOf(const CameraFragments& f, size_t j) {
  return double(f.words[3 * j + 2] & ((1u << kCoverageBits) - 1u)) / kCoverageOne;
}
double pixelCoverage(const CameraFragments& f, size_t p) {
  double sum = double(f.tail[p]) / kCoverageOne;
  for (size_t j = f.first[p]; j < f.first[p + 1]; ++j) sum += coverageOf(f, j);
  return sum;
}
float depthOf(const CameraFragments& f, size_t j) {
  return std::bit_cast<float>(f.words[3 * j + 1]);
}

// Kajiya & Kay's thin cylinder covers a pixel by its projected width × its length within the pixel: a
// strand's coverage summed down a column is its width in pixels over cos θ (its length per column), for
// strands far thinner than a pixel as for wider ones; made of many short segments, a strand is one
// fragment per pixel (its pieces there summed), not several blended over each other.
TEST(CameraFragments, AStrandCoversEachColumnByItsWidth) {
  for (const double width : {0.05, 0.2, 0.37, 1.0, 2.5})
    for (const double angle : {0.0, 0.5})
      for (const int points : {2, 200}) {
        const glm::dvec2 d(std::cos(angle), std::sin(angle));
        std::vector<glm::vec3> line;
        for (int i = 0; i < points; ++i) {
          const glm::dvec2 p = glm::dvec2(6.2, 21.7) + 50.0 / d.x * double(i) / (points - 1) * d;
          line.push_back({p.x, p.y, -1.0f});
        }
        Strands s;
        s.addStrand(line);
        const CameraFragments f = rasteriseCameraFragments(s, texelView(64), width, kKeptFragments);
        for (int x = 16; x < 48; ++x) {
          double column = 0.0;
          for (int y = 0; y < 64; ++y) {
            const size_t p = size_t(y) * 64 + size_t(x);
            column += pixelCoverage(f, p);
            EXPECT_LE(f.first[p + 1] - f.first[p], 1u) << "one strand, one fragment a pixel";
          }
          EXPECT_NEAR(column, width / d.x, 0.01 * width / d.x)
              << width << " pixels wide at " << angle << " rad, " << points << " points, column " << x;
        }
      }
}

// A strand 20 texels wide at 45° has a cross-section 28 texels tall: at its root, 14 texels below its
// first point, it reaches the band of rows (32 each) below the one that point is in (row 109 in band 3,
// its cross-section down to row 95 in band 2). Every band its cross-section reaches draws it, so each
// whole column sums to its width over cos θ, in the camera's view and in the light's maps alike.
TEST(CameraFragments, AWideDiagonalStrandIsWholeAcrossTheBands) {
  Strands s;
  s.addStrand({{40.0f, 109.0f, -1.0f}, {170.0f, 239.0f, -1.0f}});
  const double expected = 20.0 * std::sqrt(2.0);
  const CameraFragments f = rasteriseCameraFragments(s, texelView(256), 20.0, kKeptFragments);
  const HairLightMaps maps = rasteriseLightMaps(s, texelView(256), 20.0, kLayers);
  for (int x = 40; x < 170; ++x) {
    double camera = 0.0, light = 0.0;
    for (int y = 0; y < 256; ++y) {
      camera += pixelCoverage(f, size_t(y) * 256 + size_t(x));
      light += double(maps.layers[size_t(y) * 256 + size_t(x)].w) / kCoverageOne;
    }
    EXPECT_NEAR(camera, expected, 0.01 * expected) << "the camera's column " << x;
    EXPECT_NEAR(light, expected, 0.01 * expected) << "the light's column " << x;
  }
}

// Twelve strands over the same pixels, 1 cm apart in depth, added in a shuffled order: each pixel keeps
// the eight nearest, nearest first, and the four behind add their coverage to its tail.
TEST(CameraFragments, APixelKeepsItsNearestFragmentsInDepthOrderAndTheRestInItsTail) {
  Strands s;
  for (int i : {7, 2, 11, 0, 5, 9, 3, 10, 1, 6, 8, 4})
    s.addStrand({{4.0f, 10.0f, -1.0f - 0.01f * float(i)}, {60.0f, 10.0f, -1.0f - 0.01f * float(i)}});
  const CameraFragments f = rasteriseCameraFragments(s, texelView(64), 0.5, 8);
  for (int x = 10; x < 54; ++x) {
    const size_t p = 9 * 64 + size_t(x);  // the strands' row: y 10 is the edge between rows 9 and 10
    ASSERT_EQ(f.first[p + 1] - f.first[p], 8u) << x;
    for (size_t k = 0; k < 8; ++k)
      EXPECT_NEAR(depthOf(f, f.first[p] + k), 1.0 + 0.01 * double(k), 1e-6) << x << ", fragment " << k;
    double behind = 0.0;
    for (int i = 8; i < 12; ++i) behind += 0.25 / (1.0 + 0.01 * i);  // half of each width in this row
    EXPECT_NEAR(double(f.tail[p]) / kCoverageOne, behind, 1e-3) << x;
  }
}

// Twelve strands over the same pixels at the same depth: a pixel keeps the eight drawn first (equal
// depths are ordered by the first point of the fragment's first segment), and the four after add their
// coverage to its tail.
TEST(CameraFragments, AtEqualDepthsAPixelKeepsTheStrandsDrawnFirst) {
  Strands s;
  for (int i = 0; i < 12; ++i) s.addStrand({{4.0f, 10.0f, -1.0f}, {60.0f, 10.0f, -1.0f}});
  const CameraFragments f = rasteriseCameraFragments(s, texelView(64), 0.5, 8);
  for (int x = 10; x < 54; ++x) {
    const size_t p = 9 * 64 + size_t(x);
    ASSERT_EQ(f.first[p + 1] - f.first[p], 8u) << x;
    for (uint32_t k = 0; k < 8; ++k)
      EXPECT_EQ(f.words[3 * (f.first[p] + k)], 2 * k) << x << ", fragment " << k;
    EXPECT_NEAR(double(f.tail[p]) / kCoverageOne, 4 * 0.25, 1e-3) << x;  // half of each width in this row
  }
}

// What hides the hair hides it pixel by pixel, though the rasteriser skips a segment whose nearest point
// is as deep as the deepest of the head near it: a strand at 2 m over a head at 1 m, but for one pixel
// and a stretch on the right at 10 m, keeps fragments in those pixels only, at their full coverage, and
// nothing in any tail.
TEST(CameraFragments, TheHeadHidesTheHairInExactlyThePixelsWhereItIsNearer) {
  std::vector<glm::vec3> points;
  for (int i = 0; i <= 30; ++i) points.push_back({2.0f + 2.0f * float(i), 20.5f, -2.0f});
  Strands s;
  s.addStrand(points);
  std::vector<float> head(64 * 64, 1.0f);
  auto at = [](int x, int y) { return size_t(y) * 64 + size_t(x); };
  for (int y = 0; y < 64; ++y) {
    head[at(40, y)] = 10.0f;
    for (int x = 50; x < 64; ++x) head[at(x, y)] = 10.0f;
  }
  const CameraFragments f = rasteriseCameraFragments(s, texelView(64), 0.5, kKeptFragments, head.data());
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) {
      const size_t p = at(x, y);
      EXPECT_EQ(f.tail[p], 0u) << x << ", " << y;
      const bool seen = y == 20 && x >= 2 && x < 62 && (x == 40 || x >= 50);
      ASSERT_EQ(f.first[p + 1] - f.first[p], seen ? 1u : 0u) << x << ", " << y;
      if (seen) {
        EXPECT_NEAR(pixelCoverage(f, p), 0.25, 1e-3) << x;  // 0.5 m wide at 2 m: a quarter texel
      }
    }
}

// Many strands crossing in every direction: the same fragments on one thread as on all, and again.
TEST(CameraFragments, TheFragmentsAreTheSameBitsOnOneThreadAsOnAll) {
  const Strands s = crossingEveryWay();
  auto fragments = [&] { return rasteriseCameraFragments(s, texelView(256), 0.7, kKeptFragments); };
  const CameraFragments all = fragments(), again = fragments();
  tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
  const CameraFragments single = fragments();
  EXPECT_GT(all.count(), 100000u);
  EXPECT_TRUE(all.words == single.words && all.words == again.words);
  EXPECT_TRUE(all.first == single.first && all.tail == single.tail && all.tail == again.tail);
}

// The fragments a caller can use bound what is kept: as many as it can use give the same fragments,
// one fewer is an InputError before the words are gathered (so `first` never wraps past 2^32).
TEST(CameraFragments, MoreFragmentsThanTheCallerCanUseAreRefused) {
  const Strands s = crossingEveryWay();
  const raster::Bands bands = raster::projectIntoBands(s, texelView(256), 0.7);
  const CameraFragments all = cameraFragments(bands, kKeptFragments);
  const CameraFragments enough = cameraFragments(bands, kKeptFragments, nullptr, all.count());
  EXPECT_TRUE(enough.words == all.words && enough.first == all.first);
  EXPECT_THROW(cameraFragments(bands, kKeptFragments, nullptr, all.count() - 1), InputError);
}

// Samples k² draws k × k sub-pixels a pixel (k the rounded root, at most 8), fewer when the sub-pixel
// image would pass the device's largest texture: the one rule the renderer and preflight share.
TEST(CameraFragments, TheSubpixelBlockIsTheRootOfSamplesWithinTheLargestTexture) {
  RenderSettings r;
  r.resolution = {1920, 1080};
  const std::pair<int, int> samplesBlock[] = {{1, 1}, {2, 1}, {3, 2}, {4, 2}, {16, 4}, {64, 8}, {1000, 8}};
  for (const auto& [samples, block] : samplesBlock) {
    r.samples = samples;
    EXPECT_EQ(subpixelBlock(r, 16384), block) << samples;
  }
  r.samples = 64;
  EXPECT_EQ(subpixelBlock(r, 8192), 4);
  EXPECT_EQ(subpixelBlock(r, 1024), 1);
}

// A pixel the hair covers whole: its pieces' coverages are integers rounded down (hair_raster.h), so a
// strand's inside sums to within a few 1/65536 of a pixel.
constexpr float kCovered = 0.999f;

GlContext& gl() {
  static GlContext context;  // every test here needs it; failing to open one fails them (exit 3 in the CLI)
  return context;
}

// A straight strand from `a` to `b` with `n` points.
void addStraight(Strands& s, glm::vec3 a, glm::vec3 b, int n = 11) {
  std::vector<glm::vec3> p;
  for (int i = 0; i < n; ++i) p.push_back(glm::mix(a, b, float(i) / float(n - 1)));
  s.addStrand(p);
  glm::vec3 t = glm::normalize(b - a);
  for (int i = 0; i < n; ++i) s.tangents.push_back(t);
}

RenderSettings frontCamera(int size, int samples) {
  RenderSettings r;
  r.resolution = {size, size};
  r.cameraAuto = false;
  r.cameraPosition = {0.0, 0.0, 0.3};
  r.cameraTarget = {0.0, 0.0, 0.0};
  r.fieldOfView = 30.0;
  r.samples = samples;
  r.strandOpacity = 1.0;
  return r;
}

// Through the render stage, as hairgen render and run call it, with light maps of 512 texels.
RenderOutput renderStrands(const Strands& hair, const RenderSettings& r, const Mesh* head = nullptr,
                           const Visuality& v = Visuality{}, const CustomShaders& shaders = {},
                           RenderInput::LightMaps lightMaps = RenderInput::LightMaps::kAuto) {
  RenderOptions options;
  options.domResolution = 512;
  options.lightMaps = lightMaps;
  return render(gl(), hair, head, v, r, shaders, options);
}

// The light's maps drawn by hairgen's rasteriser (what every machine gets) and by OpenGL (what a custom
// HairVert gets).
constexpr RenderInput::LightMaps kBothLightMaps[] = {RenderInput::LightMaps::kCpu,
                                                     RenderInput::LightMaps::kGl};

// The world point on the plane z = 0 seen through the centre of pixel (x, y) by frontCamera.
glm::dvec3 onPlane(const RenderSettings& r, int x, int y) {
  double focal = 0.5 * r.resolution.y / std::tan(glm::radians(r.fieldOfView) * 0.5);
  double px = (x + 0.5 - 0.5 * r.resolution.x) / focal, py = (0.5 * r.resolution.y - (y + 0.5)) / focal;
  return glm::dvec3(px * r.cameraPosition.z, py * r.cameraPosition.z, 0.0);
}

// A straight strand along x carrying `normal`, ~4 pixels wide, lit from above and to the side: every
// fully covered pixel against shadeHair at the centreline, and a lone strand is not in its own shadow.
// Returns how many pixels were checked, or −1 at the first that differs.
int compareStrandWithCpu(RenderSettings r, const glm::dvec3& normal) {
  Strands s;
  addStraight(s, {-0.05f, 0, 0}, {0.05f, 0, 0});
  s.normals.assign(s.pointCount(), glm::vec3(normal));
  r.strandWidth = 0.008;
  r.lightPosition = {0.15, 0.4, 0.25};
  Visuality v;
  v.glossiness = 20.0;
  v.specularColor = {0.6, 0.6, 0.6};
  RenderOutput out = renderStrands(s, r, nullptr, v);
  int checked = 0;
  for (int y = 0; y < r.resolution.y; ++y)
    for (int x = 0; x < r.resolution.x; ++x) {
      if (out.beauty.at(kChannelOpacity, x, y) < kCovered) continue;
      glm::dvec3 p = onPlane(r, x, y);
      p.y = 0.0;  // shading is at the centreline
      const float shadow = out.beauty.at(kChannelShadow, x, y);
      glm::dvec3 expect = shadeHair(r.shadingModel, {1, 0, 0}, normal, glm::normalize(r.lightPosition - p),
                                    glm::normalize(r.cameraPosition - p), v, r, shadow);
      for (int c = 0; c < 3; ++c) {
        const float got = out.beauty.at(std::string(1, "RGB"[c]), x, y);
        if (std::abs(got - expect[c]) > 0.02 * std::max(expect[c], 0.05)) {
          ADD_FAILURE() << name(r.shadingModel) << ": pixel " << x << "," << y << " channel " << c << " is "
                        << got << ", the CPU says " << expect[c];
          return -1;
        }
      }
      EXPECT_NEAR(shadow, 1.0f, 1e-6f) << "a lone strand is not in its own shadow";
      ++checked;
    }
  return checked;
}

TEST(Render, StraightStrandMatchesKajiyaKayThesisAndAnjyoOnTheCpu) {
  for (ShadingModel model : {ShadingModel::kKajiyaKay, ShadingModel::kThesis, ShadingModel::kAnjyo}) {
    RenderSettings r = frontCamera(96, 1);
    r.shadingModel = model;
    EXPECT_GT(compareStrandWithCpu(r, {0, 0, 1}), 200) << name(model);
  }
}

// With a stored normal that leans toward the light, the volumetric model at blends 1 and 0.4: both the
// surface terms and the mix are the ones documented.
TEST(Render, VolumetricShadingMatchesTheCpuAtEachBlend) {
  for (double blend : {1.0, 0.4}) {
    RenderSettings r = frontCamera(96, 1);
    r.shadingModel = ShadingModel::kVolumetric;
    r.volumetricBlend = blend;
    EXPECT_GT(compareStrandWithCpu(r, glm::normalize(glm::dvec3(0.0, 0.5, 1.0))), 200) << "blend " << blend;
  }
}

// VolumetricBlend 0 is Kajiya-Kay: on a patch of strands whose normals point every which way, the two
// images agree within the golden thresholds (hairgen diff's 0.004 per channel), pixel by pixel.
TEST(Render, VolumetricWithBlendZeroIsKajiyaKay) {
  Strands s;
  for (int i = 0; i < 60; ++i) {
    const float y = -0.03f + 0.001f * float(i), z = 0.002f * float(i % 7);
    addStraight(s, {-0.04f, y, z}, {0.04f, y + 0.01f, z - 0.01f}, 16);
  }
  for (size_t p = 0; p < s.pointCount(); ++p)
    s.normals.push_back(
        glm::normalize(glm::vec3(std::sin(0.7f * float(p)), std::cos(1.3f * float(p)), 0.5f)));
  for (int samples : {1, 4}) {  // lines, then ribbons: the normals reach the shader both ways
    RenderSettings r = frontCamera(96, samples);
    r.strandWidth = 0.0002;
    r.lightPosition = {0.2, 0.3, 0.2};
    RenderOutput kajiyaKay = renderStrands(s, r);
    r.shadingModel = ShadingModel::kVolumetric;
    r.volumetricBlend = 0.0;
    RenderOutput volumetric = renderStrands(s, r);
    r.volumetricBlend = 1.0;
    RenderOutput full = renderStrands(s, r);
    double worst = 0.0, fullDiffers = 0.0;
    for (int y = 0; y < 96; ++y)
      for (int x = 0; x < 96; ++x)
        for (const char* c : {"R", "G", "B", "A"}) {
          worst =
              std::max(worst, double(std::abs(volumetric.beauty.at(c, x, y) - kajiyaKay.beauty.at(c, x, y))));
          fullDiffers =
              std::max(fullDiffers, double(std::abs(full.beauty.at(c, x, y) - kajiyaKay.beauty.at(c, x, y))));
        }
    EXPECT_LE(worst, 0.004) << samples << " samples";
    EXPECT_GT(fullDiffers, 0.05)
        << "blend 1 should not look like Kajiya-Kay, or the check above proves nothing";
  }
}

// A strand thinner than a pixel is a faint line, as in a photograph: its A summed across it, down each
// column, is its projected width in pixels (over cos θ when it is tilted), within 5%.
TEST(Render, AStrandsAlphaAcrossItsWidthIsItsProjectedWidth) {
  RenderSettings r = frontCamera(96, 1);
  const double focal = 0.5 * 96 / std::tan(glm::radians(15.0));  // pixels per metre at 1 m
  for (const double pixels : {0.2, 0.37, 0.8, 1.6})
    for (const double angle : {0.0, 0.4}) {
      r.strandWidth = pixels * 0.3 / focal;
      const glm::vec3 d(std::cos(angle), std::sin(angle), 0.0f);
      Strands s;
      addStraight(s, -0.06f * d, 0.06f * d, 40);
      const RenderOutput out = renderStrands(s, r);
      float largest = 0.0f;
      for (int x = 30; x < 66; ++x) {
        double column = 0.0;
        for (int y = 0; y < 96; ++y) {
          column += out.beauty.at("A", x, y);
          largest = std::max(largest, out.beauty.at("A", x, y));
        }
        EXPECT_NEAR(column, pixels / std::cos(angle), 0.05 * pixels / std::cos(angle))
            << pixels << " pixels wide at " << angle << " rad, column " << x;
      }
      if (pixels < 1.0) {
        EXPECT_LT(largest, pixels / std::cos(angle) + 0.01) << "a thin strand is faint";
      }
    }
}

// DESIGN §6: R G B A premultiplied. A pixel nothing covers is 0 in all four, A is the covered fraction of
// a pixel's sub-pixels (1 inside a strand, between 0 and 1 on its edges), and no channel exceeds what A
// allows of the brightest colour drawn.
TEST(Render, TheBeautyIsPremultiplied) {
  Strands s;
  addStraight(s, {-0.04f, -0.01f, 0}, {0.04f, 0.012f, 0});
  RenderSettings r = frontCamera(64, 4);
  r.strandWidth = 0.01;
  RenderOutput out = renderStrands(s, r);
  int edges = 0, inside = 0;
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) {
      const float a = out.beauty.at("A", x, y);
      ASSERT_GE(a, 0.0f);
      ASSERT_LE(a, 1.0f);
      if (a == 0.0f) {
        for (const char* c : {"R", "G", "B"}) ASSERT_EQ(out.beauty.at(c, x, y), 0.0f) << x << "," << y;
      }
      edges += a > 0.0f && a < kCovered;
      inside += a >= kCovered;
    }
  EXPECT_GT(edges, 20);
  EXPECT_GT(inside, 20);
}

TEST(Render, BackgroundPixelsHaveNoOpacityAndTheBackgroundZ) {
  Strands s;
  addStraight(s, {-0.02f, 0, 0}, {0.02f, 0, 0});
  RenderSettings r = frontCamera(64, 4);
  RenderOutput out = renderStrands(s, r);
  EXPECT_EQ(out.beauty.at(kChannelOpacity, 0, 0), 0.0f);
  EXPECT_EQ(out.beauty.at("A", 0, 0), 0.0f);
  EXPECT_EQ(out.beauty.at("Z", 0, 0), kBackgroundZ);
  EXPECT_EQ(out.beauty.at(kChannelShadow, 0, 0), 1.0f);
  EXPECT_EQ(out.beauty.at("R", 0, 0), 0.0f);  // premultiplied: the background is the preview's
  EXPECT_GT(out.beauty.at(kChannelOpacity, 32, 31) + out.beauty.at(kChannelOpacity, 32, 32), 0.0f);
  EXPECT_NEAR(std::min(out.beauty.at("Z", 32, 31), out.beauty.at("Z", 32, 32)), 0.3f, 1e-3f);
}

TEST(Render, AStrandBetweenTheLightAndAnotherDarkensOnlyThatOne) {
  for (RenderInput::LightMaps maps : kBothLightMaps) {
    SCOPED_TRACE(maps == RenderInput::LightMaps::kCpu ? "hairgen's light maps" : "light maps by OpenGL");
    // Light straight above; strand A 2 cm above strand B; the camera sees both from the front.
    RenderSettings r = frontCamera(96, 1);
    r.strandWidth = 0.008;
    r.lightPosition = {0.0, 1.0, 0.0};
    Strands both, aAlone, bAlone;
    addStraight(both, {-0.04f, 0.02f, 0}, {0.04f, 0.02f, 0});
    addStraight(both, {-0.04f, 0.0f, 0}, {0.04f, 0.0f, 0});
    addStraight(aAlone, {-0.04f, 0.02f, 0}, {0.04f, 0.02f, 0});
    addStraight(bAlone, {-0.04f, 0.0f, 0}, {0.04f, 0.0f, 0});
    RenderOutput all = renderStrands(both, r, nullptr, {}, {}, maps),
                 a = renderStrands(aAlone, r, nullptr, {}, {}, maps),
                 b = renderStrands(bAlone, r, nullptr, {}, {}, maps);
    int aPixels = 0, bPixels = 0;
    for (int y = 0; y < 96; ++y)
      for (int x = 20; x < 76; ++x) {
        if (a.beauty.at(kChannelOpacity, x, y) >= kCovered &&
            all.beauty.at(kChannelOpacity, x, y) >= kCovered) {
          EXPECT_NEAR(all.beauty.at("R", x, y), a.beauty.at("R", x, y), 1e-3) << "A at " << x << "," << y;
          ++aPixels;
        }
        if (b.beauty.at(kChannelOpacity, x, y) >= kCovered &&
            all.beauty.at(kChannelOpacity, x, y) >= kCovered) {
          EXPECT_LT(all.beauty.at(kChannelShadow, x, y), 0.7f);
          EXPECT_LT(all.beauty.at("R", x, y), 0.8f * b.beauty.at("R", x, y)) << "B at " << x << "," << y;
          ++bPixels;
        }
      }
    EXPECT_GT(aPixels, 50);
    EXPECT_GT(bPixels, 50);
  }
}

// Strand A, a little thinner than a texel of the light's map, 2 cm above strand B, the light straight
// above: moving A across the light's view a hundredth of a texel at a time (over a fifth of a texel,
// wherever it falls on the texel grid) changes the shadow on B by about a hundredth of the shadow's
// range each step, never by the jump of a texel (0.5 and more with a nearest-texel lookup).
TEST(Render, AStrandMovedAHundredthOfATexelChangesTheShadowByAboutAHundredth) {
  RenderSettings r = frontCamera(96, 1);
  r.fieldOfView = 6.0;  // B about a third of a pixel wide
  r.strandWidth = 1.2e-4;
  r.lightPosition = {0.0, 1.0, 0.0};
  // The light's map holds the scene's sphere at 512 texels: a texel at A's depth, in metres.
  Strands probe;
  addStraight(probe, {-0.04f, 0.02f, 0}, {0.04f, 0.02f, 0});
  addStraight(probe, {-0.04f, 0.0f, 0}, {0.04f, 0.0f, 0});
  const View light = lightView(r, boundingSphere(probe, nullptr), 512);
  const double texel = glm::length(glm::dvec3(0.0, 0.02, 0.0) - r.lightPosition) / light.focalPx;
  std::vector<float> before;
  double largest = 0.0, range = 0.0;
  for (int step = 0; step <= 20; ++step) {
    const float dz = float(0.01 * step * texel);
    Strands both;
    addStraight(both, {-0.04f, 0.02f, dz}, {0.04f, 0.02f, dz});
    addStraight(both, {-0.04f, 0.0f, 0}, {0.04f, 0.0f, 0});
    const RenderOutput out = renderStrands(both, r);
    std::vector<float> shadow;
    // B's own shadow where it covers a tenth of a pixel or more: the channel blends it with the open's 1
    // by B's coverage (its opacity).
    for (int y = 48; y < 96; ++y)  // B's half of the image: y down, B below A
      for (int x = 20; x < 76; ++x)
        if (const float a = out.beauty.at(kChannelOpacity, x, y); a > 0.1f)
          shadow.push_back(1.0f - (1.0f - out.beauty.at(kChannelShadow, x, y)) / a);
    ASSERT_GT(shadow.size(), 40u);
    for (float v : shadow) range = std::max(range, 1.0 - double(v));
    if (!before.empty() && before.size() == shadow.size())
      for (size_t i = 0; i < shadow.size(); ++i)
        largest = std::max(largest, double(std::abs(shadow[i] - before[i])));
    before = shadow;
  }
  EXPECT_GT(range, 0.1) << "A shadows B";
  EXPECT_LT(largest, 0.03 * 0.75) << "the largest change of B's shadow in one step of 1/100 texel";
}

// A flat "head" facing up, a patch of hair 5 cm above its middle (x from −2 to 2 cm), the light above
// and to the +x side (so the hair's shadow falls 2.5 cm toward −x), the camera straight above.
struct HairOverAPlane {
  Mesh head;
  Strands hair;
  RenderSettings settings;
  HairOverAPlane() {
    head.positions = {{-0.1f, 0, -0.1f}, {0.1f, 0, -0.1f}, {0.1f, 0, 0.1f}, {-0.1f, 0, 0.1f}};
    head.normals.assign(4, glm::vec3(0, 1, 0));
    head.triangles = {{0, 2, 1}, {0, 3, 2}};
    for (int i = 0; i < 40; ++i) {
      float x = -0.02f + 0.04f * i / 39.0f;
      addStraight(hair, {x, 0.05f, -0.03f}, {x, 0.05f, 0.03f});
    }
    settings.resolution = {128, 128};
    settings.samples = 1;
    settings.cameraAuto = false;
    settings.cameraPosition = {0.0, 0.5, 0.0};
    settings.cameraTarget = {0.0, 0.0, 0.0};
    settings.cameraUp = {0.0, 0.0, -1.0};
    settings.fieldOfView = 30.0;
    settings.lightPosition = {0.5, 1.0, 0.0};
    settings.strandWidth = 0.002;
    settings.strandOpacity = 0.9;
  }
  // The mean red of the head where no hair covers it, over x in (fromX, toX) metres of the middle rows.
  double headRed(const RenderOutput& out, double fromX, double toX) const {
    const double focal = 0.5 * 128 / std::tan(glm::radians(15.0));
    double sum = 0.0;
    int n = 0;
    for (int y = 54; y < 74; ++y)
      for (int x = 0; x < 128; ++x) {
        if (out.beauty.at(kChannelOpacity, x, y) != 0.0f || out.beauty.at("A", x, y) != 1.0f) continue;
        double wx = (x + 0.5 - 64) / focal * 0.5;
        if (wx > fromX && wx < toX) sum += out.beauty.at("R", x, y), ++n;
      }
    EXPECT_GT(n, 20) << "head pixels in (" << fromX << ", " << toX << ")";
    return sum / std::max(n, 1);
  }
};

TEST(Render, TheHeadIsDarkerUnderTheHairThanBesideIt) {
  for (RenderInput::LightMaps maps : kBothLightMaps) {
    HairOverAPlane scene;
    RenderOutput out = renderStrands(scene.hair, scene.settings, &scene.head, {}, {}, maps);
    EXPECT_LT(scene.headRed(out, -0.033, -0.024), 0.75 * scene.headRed(out, 0.04, 0.06));
  }
}

// hairgen's own hair vertex stage with one line added that moves every strand 5 cm along +x: the
// hair's shadow on the head moves with it, as the light's passes draw the moved hair too.
TEST(Render, ACustomHairVertexMovesTheHairAndItsShadow) {
  std::string glsl = readFileText(test::sourceDir() / "libcore/render/glsl/hair_vertex.glsl");
  const std::string anchor = "  vec4 view = uView * vec4(p, 1.0);\n";
  ASSERT_NE(glsl.find(anchor), std::string::npos);
  glsl.insert(glsl.find(anchor), "  p.x += 0.05;\n");
  test::TempDir dir("hairvert");
  writeFileAtomic(dir / "hairvert.glsl", glsl);
  hairgen::Setup setup;
  setup.hairVert = {dir / "hairvert.glsl", {"setup.txt", 8}};
  HairOverAPlane scene;
  for (int samples : {1, 4}) {  // lines, then ribbons in the shading pass
    scene.settings.samples = samples;
    RenderOutput out =
        renderStrands(scene.hair, scene.settings, &scene.head, Visuality{}, readCustomShaders(setup));
    EXPECT_LT(scene.headRed(out, 0.017, 0.026), 0.75 * scene.headRed(out, -0.033, -0.024))
        << samples << " samples";
  }
}

// Each pixel's hair is its analytic coverage (camera_fragments.h), so a lone strand needs no
// supersampling: Samples 9 changes no pixel by more than a few hundredths, and none away from the
// strand's edges by more than 0.01 (what it still changes there is where in the pixel the strand is
// shaded).
TEST(Render, SupersamplingChangesALoneStrandLittle) {
  Strands s;
  addStraight(s, {-0.05f, -0.01f, 0}, {0.05f, 0.012f, 0});
  RenderSettings r = frontCamera(80, 1);
  r.strandWidth = 0.01;
  r.lightPosition = {0.1, 0.3, 0.3};
  RenderOutput one = renderStrands(s, r);
  r.samples = 9;
  RenderOutput nine = renderStrands(s, r);
  int edges = 0;
  double edgeChange = 0.0;
  for (int y = 1; y < 79; ++y)
    for (int x = 1; x < 79; ++x) {
      // An edge pixel: partly covered, or next to one that is.
      bool edge = false;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const float a = one.beauty.at(kChannelOpacity, x + dx, y + dy);
          edge = edge || (a > 0.0f && a < kCovered);
        }
      double change = 0.0;
      for (const char* c : {"R", "G", "B", "A"})
        change = std::max(change, double(std::abs(one.beauty.at(c, x, y) - nine.beauty.at(c, x, y))));
      if (!edge) {
        ASSERT_LT(change, 0.01) << "pixel " << x << "," << y << " is not on an edge";
      } else {
        ++edges;
        edgeChange = std::max(edgeChange, change);
      }
    }
  EXPECT_GT(edges, 100);
  EXPECT_LT(edgeChange, 0.05) << "the largest change at an edge";
}

// A Setup naming `glsl` as its HairFrag at setup.txt:9, the file written to `dir` and read back as
// hairgen render and run read it.
CustomShaders customHairFrag(const test::TempDir& dir, const std::string& glsl) {
  writeFileAtomic(dir / "hairfrag.glsl", glsl);
  hairgen::Setup setup;
  setup.hairFrag = {dir / "hairfrag.glsl", {"setup.txt", 9}};
  return readCustomShaders(setup);
}

TEST(Render, ACustomHairFragmentGivesItsColorWhereTheHairIs) {
  test::TempDir dir("hairfrag");
  const CustomShaders shaders =
      customHairFrag(dir,
                     "in float vAlpha;\n"
                     "in float vDepth;\n"
                     "layout(location = 0) out vec4 oColor;\n"
                     "layout(location = 1) out vec4 oData;\n"
                     "void main() {\n"
                     "  screenDoor(vAlpha);\n"
                     "  oColor = vec4(0.25, 0.75, 0.5, vAlpha);\n"
                     "  oData = vec4(vDepth, 1.0, lightArriving(vec3(0.0), 0.0), 0.0);\n"
                     "}\n");
  Strands s;
  addStraight(s, {-0.04f, 0, 0}, {0.04f, 0, 0});
  RenderSettings r = frontCamera(64, 1);
  r.strandWidth = 0.012;
  RenderOutput out = renderStrands(s, r, nullptr, Visuality{}, shaders);
  int hair = 0;
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) {
      if (out.beauty.at(kChannelOpacity, x, y) < kCovered) continue;
      EXPECT_NEAR(out.beauty.at("R", x, y), 0.25f, 1e-3f) << x << "," << y;
      EXPECT_NEAR(out.beauty.at("G", x, y), 0.75f, 1e-3f) << x << "," << y;
      EXPECT_NEAR(out.beauty.at("B", x, y), 0.5f, 1e-3f) << x << "," << y;
      ++hair;
    }
  EXPECT_GT(hair, 40);
  EXPECT_EQ(out.beauty.at(kChannelOpacity, 0, 0), 0.0f);
  EXPECT_EQ(out.beauty.at("R", 0, 0), 0.0f) << "the background is not the shader's, nor the image's";
}

TEST(Render, ABrokenCustomHairFragmentIsAnInputErrorAtItsFileAndLine) {
  test::TempDir dir("hairfrag");
  const CustomShaders shaders = customHairFrag(dir,
                                               "layout(location = 0) out vec4 oColor;\n"
                                               "layout(location = 1) out vec4 oData;\n"
                                               "void main() {\n"
                                               "  oColor = vec4(foo);\n"
                                               "  oData = vec4(0.0);\n"
                                               "}\n");
  Strands s;
  addStraight(s, {-0.04f, 0, 0}, {0.04f, 0, 0});
  try {
    renderStrands(s, frontCamera(32, 1), nullptr, Visuality{}, shaders);
    FAIL() << "a HairFrag that does not compile rendered";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_EQ(e.code(), ExitCode::kBadInput);
    EXPECT_EQ(e.where().line, 4) << what;
    EXPECT_EQ(what.rfind((dir / "hairfrag.glsl").string() + ":4: ", 0), 0u) << what;
    EXPECT_NE(what.find("foo"), std::string::npos) << what;
    EXPECT_NE(what.find("HairFrag, named at setup.txt:9"), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << "one line: " << what;
  }
}

// A driver's compiler took 6 GB and 20 s for one statement of 5,000 additions and crashed at 20,000;
// it inlines every function, and a macro used in a macro doubles. What a custom stage asks of it is
// bounded before it sees it, each refusal at the file's line; every stage of hairgen's own, of any size
// it has, passes.
TEST(Render, ACustomStageTooLargeForACompilerIsRefusedAtItsLine) {
  for (const std::filesystem::directory_entry& f :
       std::filesystem::directory_iterator(test::sourceDir() / "libcore" / "render" / "glsl"))
    EXPECT_NO_THROW(requireBoundedStage({readFileText(f.path()), f.path().string(), ""})) << f.path();
  auto refusal = [](const std::string& text) {
    try {
      requireBoundedStage({text, "f.glsl", ""});
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  auto refusedAt = [&](const std::string& text, const std::string& start) {
    const std::string m = refusal(text);
    EXPECT_EQ(m.rfind(start, 0), 0u) << m;
  };
  std::string sum = "void main() {\n  float s = 0.0\n";
  for (int i = 0; i < 1100; ++i) sum += "    + 1.0\n";
  refusedAt(sum + "    ;\n}\n", "f.glsl:2: a statement of more than 1024 operators");
  // A swizzle chain is as long as its member accesses; a table of constants, however long, has few
  // operators (a flat list, cheap for a compiler); CR and CRLF end a directive as LF does.
  std::string chain = "vec4 c = vec4(1.0)";
  for (int i = 0; i < 1100; ++i) chain += ".wzyx";
  refusedAt(chain + ";\n", "f.glsl:1: a statement of more than 1024 operators");
  std::string table = "const vec2 kDisk[256] = vec2[](";
  for (int i = 0; i < 256; ++i) table += std::string(i ? ", " : "") + "vec2(0.25, 0.75)";
  EXPECT_EQ(refusal(table + ");\n"), "accepted");
  refusedAt("#define X 1.0\r" + sum + "    ;\r}\r", "f.glsl:3: a statement of more than 1024 operators");
  std::string doubling = "float f0(float x) { return x; }\n";
  for (int i = 1; i <= 20; ++i)
    doubling += "float f" + std::to_string(i) + "(float x) { return f" + std::to_string(i - 1) + "(x) + f" +
                std::to_string(i - 1) + "(x); }\n";
  EXPECT_NE(refusal(doubling).find("with the functions it calls inlined is more than 100000 tokens"),
            std::string::npos);
  // Macros built of macros, in either order, or redefined after an #undef: the largest expansion counts.
  std::string macros = "#define A0 x\n";
  for (int i = 1; i <= 20; ++i)
    macros += "#define A" + std::to_string(i) + " (A" + std::to_string(i - 1) + " + A" +
              std::to_string(i - 1) + ")\n";
  refusedAt(macros + "float y = A20;\n", "f.glsl:22: a statement of more than 1024 operators");
  std::string reversed;
  for (int i = 20; i >= 1; --i)
    reversed += "#define B" + std::to_string(i) + " (B" + std::to_string(i - 1) + " + B" +
                std::to_string(i - 1) + ")\n";
  refusedAt(reversed + "#define B0 x\nfloat y = B20;\n",
            "f.glsl:22: a statement of more than 1024 operators");
  refusedAt(macros + "#undef A20\n#define A20 1.0\nfloat y = A20;\n", "f.glsl:24: a statement of more than");
  // Macros as shaders use them pass; a function-like one's use costs its body and each argument as many
  // times as its parameter appears there, and nested ones (which expand without bound) are refused, an
  // object-like alias of one too.
  const std::string twice = "// a note\n#define TWICE(a) ((a) + (a))\n#define HALF (0.5)\n";
  EXPECT_EQ(refusal(twice + "float y = TWICE(HALF) * HALF;\n"), "accepted");
  refusedAt(twice + "float y = TWICE(TWICE(HALF));\n", "f.glsl:4: the function-like macro TWICE");
  refusedAt(twice + "#define FOUR(a) TWICE(TWICE(a))\n", "f.glsl:4: #define FOUR(...) uses");
  refusedAt(twice + "#define G TWICE\nfloat y = G(G(1.0));\n", "f.glsl:5: the function-like macro G");
  refusedAt("#define CAT(a, b) a##b\n", "f.glsl:1: ## (token pasting)");
  std::string many = "#define MANY(a) (a";
  for (int i = 0; i < 600; ++i) many += " + a";
  many += ")\n";
  EXPECT_EQ(refusal(many + "float y = MANY(1.0);\n"), "accepted");
  refusedAt(many + "float y = MANY(1.0 + 2.0);\n", "f.glsl:2: a statement of more");
  refusedAt("float y = " + std::string(65, '(') + "1.0" + std::string(65, ')') + ";\n",
            "f.glsl:1: parentheses, brackets and braces nested more than 64 deep");
  // Nesting inside a macro's body counts where the macro is used.
  refusedAt(
      "#define OPEN ((((((((((((((((((((((((((((((((1.0))))))))))))))))))))))))))))))))\n"
      "float y = ((((((((((((((((((((((((((((((((((OPEN))))))))))))))))))))))))))))))))));\n",
      "f.glsl:2: parentheses, brackets and braces nested more than 64 deep");
}

// Where the rasteriser's fragments are shaded (the atlas), a HairFrag's inputs are globals hairgen sets:
// each `in` declaration of them, however qualified, loses its qualifiers and nothing else (every line
// and column stays the file's), and hairgen's main() after the file sets the names it declared.
TEST(Render, TheAtlasMakesAHairFragsInputDeclarationsGlobalsAndKeepsItsColumns) {
  const std::string body =
      "layout(location = 0) in vec3 vWorld, vTangent;\n"
      "in flat\n"
      "  vec3 vColor /* strand colour */;\n"
      "in vec3 vWorld2, vNormal;\n"
      "in vec3 vOther;\n"
      "float f(in float x) { return x; }  // in vec3 vNormal;\n"
      "void main() {}\n";
  const std::string text = assembleStage({.atlas = true}, body);
  const std::string own = text.substr(text.rfind("#line 1\n") + 8);
  ASSERT_EQ(own.substr(0, body.size()).size(), body.size());
  const std::string kept = own.substr(0, body.size());
  const std::string expected =
      "                        vec3 vWorld, vTangent;\n"
      "       \n"
      "  vec3 vColor /* strand colour */;\n"
      "in vec3 vWorld2, vNormal;\n"  // not all hair inputs: left as it is
      "in vec3 vOther;\n"
      "float f(in float x) { return x; }  // in vec3 vNormal;\n"
      "void main() {}\n";
  EXPECT_EQ(kept, expected);
  const std::string after = own.substr(body.size());
  for (const char* set : {"vWorld = ", "vTangent = ", "vColor = ", "hairgenShade();"})
    EXPECT_NE(after.find(set), std::string::npos) << set << " not in:\n" << after;
  for (const char* unset : {"vNormal = ", "vAlpha = ", "vDepth = ", "hairgenAtlasRows - 1"})
    EXPECT_EQ(after.find(unset), std::string::npos) << unset << " in:\n" << after;
  EXPECT_NE(assembleStage({}, body).find(body), std::string::npos) << "only the atlas' stages change";
  EXPECT_EQ(assembleStage({.atlas = true}, "in float vAlpha;\n").find("hairgenShade();"), std::string::npos)
      << "no main(): none of hairgen's either, so the linker says what is missing";
}

// The same through the renderer: hairgen's own HairFrag text with its inputs declared as a TD might
// write them (two to a declaration, qualifiers in another order, comments, gl_FragCoord redeclared with
// rows from the top) shades the rasteriser's fragments as hairgen's own stage does, over an atlas of
// several rows; and a compiler error in it keeps the file's line.
TEST(Render, AHairFragsInputsReachItWhateverItsDeclarationsLookLike) {
  test::TempDir dir("hairfrag");
  const std::string own =
      readFileText(test::sourceDir() / "libcore" / "render" / "glsl" / "hair_fragment.glsl");
  const std::string declarations =
      "in vec3 vWorld;\nin vec3 vTangent;\nin vec3 vColor;\nin vec3 vNormal;\nin float vAlpha;\nin float "
      "vDepth;\n";
  const size_t at = own.find(declarations);
  ASSERT_NE(at, std::string::npos) << "hair_fragment.glsl declares its inputs otherwise now";
  const std::string odd =
      "layout(location = 0) in vec3 vWorld, vTangent;  // two at once\n"
      "in flat vec3 vColor;\n"
      "smooth in /* a comment */ vec3 vNormal;\n"
      "in float vAlpha /* coverage x StrandOpacity */;\n"
      "layout(origin_upper_left) in vec4 gl_FragCoord;\n"
      "in float vDepth;\n";
  const std::string text = own.substr(0, at) + odd + own.substr(at + declarations.size());
  Strands s;
  for (int k = 0; k < 40; ++k) {
    const float y = -0.035f + 0.07f * float(k) / 39.0f;
    addStraight(s, {-0.04f, y, 0.01f * float(k % 3)}, {0.04f, y + 0.01f, 0.0f});
  }
  RenderSettings r = frontCamera(128, 1);
  r.strandWidth = 0.002;
  r.strandOpacity = 0.6;
  const RenderOutput reference = renderStrands(s, r);
  const RenderOutput custom = renderStrands(s, r, nullptr, Visuality{}, customHairFrag(dir, text));
  ASSERT_GT(custom.hairFragments, 4096u) << "an atlas of two rows or more";
  int hair = 0;
  for (const char* c : {"R", "G", "B", "A"})
    for (int y = 0; y < 128; ++y)
      for (int x = 0; x < 128; ++x) {
        ASSERT_NEAR(custom.beauty.at(c, x, y), reference.beauty.at(c, x, y), 2e-3f)
            << c << " " << x << "," << y;
        hair += std::string(c) == "A" && reference.beauty.at(c, x, y) > 0.1f;
      }
  EXPECT_GT(hair, 2000);
  const size_t mainAt = text.find("void main()");
  const int mainLine = int(std::count(text.begin(), text.begin() + ptrdiff_t(mainAt), '\n')) + 1;
  std::string broken = text;
  broken.insert(text.find('\n', mainAt) + 1, "  foo = 1;\n");
  try {
    renderStrands(s, r, nullptr, Visuality{}, customHairFrag(dir, broken));
    FAIL() << "a HairFrag that does not compile rendered";
  } catch (const InputError& e) {
    EXPECT_EQ(e.where().line, mainLine + 1) << e.what();
  }
}

TEST(Render, CompilerLogsFoldToTheirFirstErrorAndItsLine) {
  CompilerMessage mesa = firstCompilerError(
      "0:3(10): warning: `x' unused\n0:12(5): error: `foo' undeclared\n0:13(2): error: syntax error\n");
  EXPECT_EQ(mesa.line, 12);
  EXPECT_EQ(mesa.text, "`foo' undeclared");
  CompilerMessage nvidia = firstCompilerError("0(12) : error C1008: undefined variable \"foo\"\n");
  EXPECT_EQ(nvidia.line, 12);
  EXPECT_EQ(nvidia.text, "error C1008: undefined variable \"foo\"");
  CompilerMessage glslang =
      firstCompilerError("ERROR: 0:12: 'foo' : undeclared identifier\nERROR: 1 compilation errors.\n");
  EXPECT_EQ(glslang.line, 12);
  EXPECT_EQ(glslang.text, "'foo' : undeclared identifier");
  CompilerMessage link = firstCompilerError("error: vertex shader lacks `main'\n");
  EXPECT_EQ(link.line, 0);
  EXPECT_EQ(link.text, "vertex shader lacks `main'");
}

// Hair made in centimetres with z up: after conform, y is up and lengths are metres.
TEST(Render, ConformTurnsZUpCentimetresIntoYUpMetres) {
  Strands s;
  s.addStrand({{0, 0, 0}, {1, 2, 30}});
  s.tangents = {{0, 0, 1}, {0, 0, 1}};
  s.thickness = {0.008f, 0.008f};
  conform(s, true, 0.01);
  EXPECT_NEAR(s.points[1].x, 0.01f, 1e-7f);
  EXPECT_NEAR(s.points[1].y, 0.30f, 1e-7f);
  EXPECT_NEAR(s.points[1].z, -0.02f, 1e-7f);
  EXPECT_EQ(s.tangents[0], glm::vec3(0, 1, 0));
  EXPECT_NEAR(s.thickness[0], 8e-5f, 1e-10f);
}

// The hair over its plane a frame after `before`: the hair 2 mm toward +x (image right) and 1 mm toward
// −z (image up), the plane 1 mm toward +z (image down). Their motion vectors are those moves over their
// depth (0.45 m and 0.5 m) in pixels; where nothing is drawn, 0. Lines and ribbons alike.
TEST(Render, MotionVectorsAreTheMoveOnTheImageInPixels) {
  HairOverAPlane before, after;
  before.settings.strandWidth = after.settings.strandWidth = 0.006;  // 3 pixels: their middles covered whole
  for (glm::vec3& p : after.hair.points) p += glm::vec3(0.002f, 0.0f, -0.001f);
  for (glm::vec3& p : after.head.positions) p += glm::vec3(0.0f, 0.0f, 0.001f);
  const double focal = 0.5 * 128 / std::tan(glm::radians(15.0));
  for (int samples : {1, 4}) {
    after.settings.samples = samples;
    after.settings.strandOpacity = 1.0;
    RenderOptions options;
    options.domResolution = 512;
    const FrameBefore frameBefore{&before.hair, &before.head};
    RenderOutput out =
        render(gl(), after.hair, &after.head, Visuality{}, after.settings, {}, options, &frameBefore);
    ASSERT_EQ(out.beauty.channels.back(), kChannelMotionV);
    int hair = 0, head = 0;
    for (int y = 0; y < 128; ++y)
      for (int x = 0; x < 128; ++x) {
        const float u = out.beauty.at(kChannelMotionU, x, y), v = out.beauty.at(kChannelMotionV, x, y);
        if (out.beauty.at(kChannelOpacity, x, y) >= kCovered) {
          ASSERT_NEAR(u, 0.002 * focal / 0.45, 2e-3) << samples << " samples, hair at " << x << "," << y;
          ASSERT_NEAR(v, 0.001 * focal / 0.45, 2e-3) << samples << " samples, hair at " << x << "," << y;
          ++hair;
        } else if (out.beauty.at(kChannelOpacity, x, y) == 0.0f && out.beauty.at("A", x, y) == 1.0f) {
          ASSERT_NEAR(u, 0.0, 2e-3) << samples << " samples, head at " << x << "," << y;
          ASSERT_NEAR(v, -0.001 * focal / 0.5, 2e-3) << samples << " samples, head at " << x << "," << y;
          ++head;
        } else if (out.beauty.at("A", x, y) == 0.0f) {
          ASSERT_EQ(u, 0.0f);
          ASSERT_EQ(v, 0.0f);
        }
      }
    EXPECT_GT(hair, 500) << samples << " samples";
    EXPECT_GT(head, 2000) << samples << " samples";
  }
}

// The motion pass draws after the shading pass and changes none of its channels; a frame with nothing
// moved has motion vectors of exactly 0.
TEST(Render, MotionVectorsChangeNothingElseAndAreZeroForAStill) {
  HairOverAPlane scene;
  scene.settings.samples = 4;
  RenderOptions options;
  options.domResolution = 512;
  const FrameBefore still{&scene.hair, &scene.head};
  RenderOutput plain = render(gl(), scene.hair, &scene.head, Visuality{}, scene.settings, {}, options);
  RenderOutput moving =
      render(gl(), scene.hair, &scene.head, Visuality{}, scene.settings, {}, options, &still);
  ASSERT_EQ(moving.beauty.channels.size(), plain.beauty.channels.size() + 2);
  for (size_t c = 0; c < plain.beauty.channels.size(); ++c) {
    EXPECT_EQ(moving.beauty.channels[c], plain.beauty.channels[c]);
    EXPECT_EQ(moving.beauty.planes[c], plain.beauty.planes[c]) << plain.beauty.channels[c];
  }
  for (size_t c = plain.beauty.channels.size(); c < moving.beauty.channels.size(); ++c)
    for (float m : moving.beauty.planes[c]) ASSERT_EQ(m, 0.0f) << moving.beauty.channels[c];
}

// A custom HairVert may move the strands in ways the motion pass (hairgen's own vertex stage) cannot
// follow, so motion vectors with one are refused rather than wrong; so are frames of other strands.
TEST(Render, MotionVectorsRefuseACustomHairVertexAndOtherStrands) {
  test::TempDir dir("motionvert");
  writeFileAtomic(dir / "hairvert.glsl",
                  readFileText(test::sourceDir() / "libcore/render/glsl/hair_vertex.glsl"));
  hairgen::Setup setup;
  setup.hairVert = {dir / "hairvert.glsl", {"setup.txt", 8}};
  HairOverAPlane scene;
  RenderOptions options;
  const FrameBefore still{&scene.hair, &scene.head};
  EXPECT_THROW(render(gl(), scene.hair, &scene.head, Visuality{}, scene.settings, readCustomShaders(setup),
                      options, &still),
               InputError);
  Strands fewer = scene.hair;
  fewer.firstPoint.pop_back();
  fewer.points.resize(fewer.firstPoint.back());
  const FrameBefore other{&fewer, &scene.head};
  EXPECT_THROW(render(gl(), scene.hair, &scene.head, Visuality{}, scene.settings, {}, options, &other),
               InputError);
}

// Hair large enough to be read in place (more than 8 MiB of points) gives the same image read in place
// as copied, and the caller is told once when it may free it.
TEST(Render, HairReadInPlaceGivesTheImageOfACopy) {
  Strands hair;
  for (int i = 0; i < 12000; ++i) {
    const float x = -0.05f + 0.1f * float(i % 120) / 119.0f, z = -0.02f + 0.04f * float(i / 120) / 99.0f;
    addStraight(hair, {x, 0.03f, z}, {x + 0.01f, -0.04f, z}, 64);
  }
  RenderSettings r = frontCamera(128, 1);
  r.lightPosition = {0.1, 0.5, 0.3};
  std::vector<RenderOutput> outs;
  for (bool inPlace : {true, false}) {
    Strands mine = hair;
    RenderInput in;
    in.hair = &mine;
    in.settings = r;
    in.domResolution = 512;
    in.readInPlace = inPlace;
    int told = 0;
    // Once told, the caller may do anything with its hair: spoiling it must not reach the image.
    in.uploaded = [&] {
      ++told;
      std::fill(mine.points.begin(), mine.points.end(), glm::vec3(std::numeric_limits<float>::quiet_NaN()));
    };
    outs.push_back(renderHair(gl(), in));
    EXPECT_EQ(told, 1);
  }
  EXPECT_EQ(outs[0].hairReadInPlace, contextReadsInPlace());
  EXPECT_FALSE(outs[1].hairReadInPlace);
  EXPECT_TRUE(outs[0].beauty.planes == outs[1].beauty.planes);
}

// Coupe 3 at a fifth of its density with its head and Render Info at 320×240: the light's maps from
// hairgen's rasteriser (every machine's) and from OpenGL's lines (a custom HairVert's) hold about as much
// opacity in all: OpenGL's lines cover a texel per step along the major axis, so a segment at angle θ to
// it counts cos θ of its length (0.71-1). (The nearer layers differ more: the rasteriser's start is the
// nearest strand that reaches a texel through its footprint, its cross-section through the texels'
// tents, a line's the nearest through its one texel.) The two give the same picture but for the
// shadows' edges: under a tenth of the hair's pixels differ by more than 0.1.
TEST(Render, TheRasterisersLightMapsAreOpenGlsLines) {
  test::Job job = test::loadJob("thesis/coupe3/setup.txt", SetupUse::kRender);
  const Strands coupe = test::coupeOf(job, 20);
  const Mesh head = readObj(job.config.setup.headModel.path);
  RenderSettings r = job.config.render;
  r.resolution = {320, 240};
  r.samples = 1;
  RenderOptions options;
  options.keepDom = true;
  options.domResolution = 1024;
  options.lightMaps = RenderInput::LightMaps::kCpu;
  const RenderOutput own = render(gl(), coupe, &head, job.config.visuality, r, {}, options);
  options.lightMaps = RenderInput::LightMaps::kGl;
  const RenderOutput ogl = render(gl(), coupe, &head, job.config.visuality, r, {}, options);
  double ownSum = 0.0, oglSum = 0.0;
  for (int y = 0; y < own.dom.height; ++y)
    for (int x = 0; x < own.dom.width; ++x) {
      ownSum += own.dom.at(kChannelDomLayers[3], x, y);
      oglSum += ogl.dom.at(kChannelDomLayers[3], x, y);
    }
  EXPECT_GT(oglSum, 0.7 * ownSum);
  EXPECT_LT(oglSum, 1.02 * ownSum);
  size_t pixels = 0, shadowed = 0;
  for (int y = 0; y < 240; ++y)
    for (int x = 0; x < 320; ++x) {
      if (own.beauty.at(kChannelOpacity, x, y) == 0.0f) continue;
      ++pixels;
      shadowed += std::abs(own.beauty.at(kChannelShadow, x, y) - ogl.beauty.at(kChannelShadow, x, y)) > 0.1f;
    }
  EXPECT_GT(pixels, 5000u);
  EXPECT_LT(double(shadowed), 0.1 * double(pixels)) << shadowed << " of " << pixels << " pixels";
}

// Left to the renderer, the light's maps follow the image: at the scene's centre a texel is no larger
// than a pixel (between kMinDomResolution and kMaxDomResolution texels a side), so a larger image gets
// larger maps.
TEST(Render, TheLightsMapsFollowTheImage) {
  Strands s;
  addStraight(s, {-0.04f, 0.02f, 0}, {0.04f, 0.02f, 0});
  addStraight(s, {-0.04f, 0.0f, 0}, {0.04f, 0.0f, 0});
  RenderOptions options;
  options.keepDom = true;
  int previous = 0;
  for (int size : {64, 1200, 3000}) {
    RenderSettings r = frontCamera(size, 1);
    r.lightPosition = {0.0, 1.0, 0.0};
    const RenderOutput out = render(gl(), s, nullptr, Visuality{}, r, {}, options);
    const BoundingSphere sphere = boundingSphere(s, nullptr);
    const View light = lightView(r, sphere, out.dom.width), camera = cameraView(r, sphere);
    const double texel = glm::length(sphere.centre - r.lightPosition) / light.focalPx;
    const double pixel = glm::length(sphere.centre - r.cameraPosition) / camera.focalPx;
    EXPECT_GE(out.dom.width, kMinDomResolution) << size;
    EXPECT_LE(out.dom.width, kMaxDomResolution) << size;
    if (out.dom.width > kMinDomResolution && out.dom.width < kMaxDomResolution) {
      EXPECT_LE(texel, pixel) << size;
      EXPECT_GT(texel, 0.99 * pixel * (out.dom.width - 1) / out.dom.width)
          << size << ": no larger than it needs";
    }
    EXPECT_GT(out.dom.width, previous) << size;
    previous = out.dom.width;
  }
}

// After framing, the camera looks at the hair's centre from the same direction, and the hair's
// bounding sphere lies inside the narrower field of view.
// OpenEXR's camera attributes (issue 34): world points projected with the written header's matrices
// as a compositor does it, with Imath's row vectors (p' = p M, then the divide by w), land on the
// pixels where the points were drawn, and worldToCamera puts them in front of the camera (z > 0) at
// the depth the Z channel holds. An oblique camera and a wide image, so a transposed matrix, a flipped
// axis or a lost aspect ratio each moves a point by many pixels.
TEST(Render, TheExrCameraAttributesFindDrawnPointsAtTheirPixels) {
  RenderSettings r = frontCamera(64, 1);
  r.resolution = {160, 90};
  r.cameraPosition = {0.06, 0.04, 0.3};
  r.cameraTarget = {0.01, -0.01, 0.0};
  r.cameraUp = {0.1, 1.0, 0.0};
  const glm::vec3 points[] = {{-0.05f, 0.03f, 0.0f},
                              {0.05f, -0.02f, 0.02f},
                              {0.0f, 0.0f, -0.03f},
                              {0.045f, 0.035f, -0.01f},
                              {-0.04f, -0.04f, 0.03f}};
  test::TempDir dir("exr-camera");
  for (const glm::vec3& p : points) {
    // A cross of two strands 2 cm long centred on the point (3 pixels at this distance): the centre of
    // what they cover is the point's pixel, to a small fraction of one.
    Strands s;
    addStraight(s, p - glm::vec3(0.01f, 0.0f, 0.0f), p + glm::vec3(0.01f, 0.0f, 0.0f));
    addStraight(s, p - glm::vec3(0.0f, 0.01f, 0.0f), p + glm::vec3(0.0f, 0.01f, 0.0f));
    const RenderOutput out = renderStrands(s, r);
    ExrMetadata meta;
    meta.camera = true;
    meta.worldToCamera = out.worldToCamera;
    meta.worldToNdc = out.worldToNdc;
    writeExr(dir / "dot.exr", out.beauty, meta);
    Imf::InputFile file((dir / "dot.exr").c_str());
    ASSERT_TRUE(Imf::hasWorldToNDC(file.header()) && Imf::hasWorldToCamera(file.header()));
    const Imath::M44f toNdc = Imf::worldToNDC(file.header()), toCamera = Imf::worldToCamera(file.header());
    Imath::V3f ndc, camera;
    toNdc.multVecMatrix(Imath::V3f(p.x, p.y, p.z), ndc);
    toCamera.multVecMatrix(Imath::V3f(p.x, p.y, p.z), camera);
    // Where it was drawn: the coverage-weighted centre of the pixels it covers (pixel x's centre x + ½).
    double weight = 0.0, x = 0.0, y = 0.0;
    for (int j = 0; j < r.resolution.y; ++j)
      for (int i = 0; i < r.resolution.x; ++i)
        if (const double a = out.beauty.at("A", i, j); a > 0.0) {
          weight += a;
          x += a * (i + 0.5);
          y += a * (j + 0.5);
        }
    ASSERT_GT(weight, 0.0) << "the dot at " << p.x << "," << p.y << "," << p.z << " was not drawn";
    EXPECT_NEAR(ndc.x * r.resolution.x, x / weight, 1.0) << "point " << p.x << "," << p.y << "," << p.z;
    EXPECT_NEAR(ndc.y * r.resolution.y, y / weight, 1.0) << "point " << p.x << "," << p.y << "," << p.z;
    EXPECT_GT(camera.z, 0.0f) << "in front of the camera";
    const int i = int(std::floor(ndc.x * r.resolution.x)), j = int(std::floor(ndc.y * r.resolution.y));
    ASSERT_TRUE(i >= 0 && i < r.resolution.x && j >= 0 && j < r.resolution.y);
    EXPECT_NEAR(camera.z, out.beauty.at("Z", i, j), 1e-3) << "the Z channel's depth at the point's pixel";
  }
}

TEST(Render, FrameHairAimsAtTheHairAndFitsItInTheView) {
  Strands s;
  addStraight(s, {1.0f, 2.0f, 3.0f}, {1.5f, 2.2f, 3.1f});
  RenderSettings r;
  r.resolution = {200, 100};
  const glm::dvec3 from = glm::normalize(r.cameraPosition - r.cameraTarget);
  frameHair(r, s);
  const glm::dvec3 centre(1.25, 2.1, 3.05);
  EXPECT_NEAR(glm::length(r.cameraTarget - centre), 0.0, 1e-6);
  EXPECT_NEAR(glm::dot(glm::normalize(r.cameraPosition - r.cameraTarget), from), 1.0, 1e-9);
  const double radius = 0.5 * glm::length(glm::dvec3(0.5, 0.2, 0.1));
  const double halfAngle = std::asin(radius / glm::length(r.cameraPosition - centre));
  EXPECT_LT(halfAngle, 0.5 * glm::radians(r.fieldOfView) * 0.99);
}

}  // namespace
}  // namespace hairgen
