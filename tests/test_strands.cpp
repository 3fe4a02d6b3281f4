// The strand model's helpers (libcore/model/strands.h): cutting a set of strands down to some of them.
#include <gtest/gtest.h>

#include "libcore/model/strands.h"
#include "tests/test_util.h"

namespace hairgen {
namespace {

// sampleStrands with one-point strands (bare follicles) at the start, in the middle, two in a row and at
// the end, each carrying every attribute as the others do.
Strands withFollicles() {
  Strands s = test::sampleStrands(9, 5);
  Strands out;
  const std::vector<bool> follicleBefore = {true, false, false, false, true, true, false, false, false};
  auto copyStrand = [&](size_t i, size_t points) {
    std::vector<glm::vec3> p(s.points.begin() + s.firstPoint[i], s.points.begin() + s.firstPoint[i] + points);
    out.addStrand(p);
    for (uint32_t k = s.firstPoint[i]; k < s.firstPoint[i] + points; ++k) {
      out.tangents.push_back(s.tangents[k]);
      out.normals.push_back(s.normals[k]);
      out.colors.push_back(s.colors[k]);
      out.thickness.push_back(s.thickness[k]);
      out.transparency.push_back(s.transparency[k]);
    }
    out.strandId.push_back(s.strandId[i] + (points == 1 ? 500 : 0));
    out.rootTriangle.push_back(s.rootTriangle[i]);
    out.rootBary.push_back(s.rootBary[i]);
    out.rootUv.push_back(s.rootUv[i]);
    out.guideIds.push_back(s.guideIds[i]);
    out.guideWeights.push_back(s.guideWeights[i]);
  };
  for (size_t i = 0; i < s.strandCount(); ++i) {
    if (follicleBefore[i]) copyStrand(i, 1);
    copyStrand(i, s.pointsOf(i));
  }
  copyStrand(0, 1);
  out.defaultThickness = 8e-5f;
  out.defaultTransparency = 0.125f;
  out.defaultColor = glm::vec3(0.1f, 0.2f, 0.3f);
  out.provenance = s.provenance;
  out.simulationState = {1.0, 2.0, 3.0};
  return out;
}

// Every per-point and per-strand array of `kept` holds, in order, the entries of `from`'s strands
// `which`; defaults and provenance are `from`'s.
void expectStrandsOf(const Strands& kept, const Strands& from, const std::vector<size_t>& which) {
  ASSERT_EQ(kept.strandCount(), which.size());
  size_t points = 0;
  for (size_t i : which) points += from.pointsOf(i);
  for (size_t size : {kept.points.size(), kept.tangents.size(), kept.normals.size(), kept.colors.size(),
                      kept.thickness.size(), kept.transparency.size()})
    ASSERT_EQ(size, points);
  for (size_t size : {kept.strandId.size(), kept.rootTriangle.size(), kept.rootBary.size(),
                      kept.rootUv.size(), kept.guideIds.size(), kept.guideWeights.size()})
    ASSERT_EQ(size, which.size());
  kept.validate("kept");
  size_t point = 0;
  for (size_t k = 0; k < which.size(); ++k) {
    const size_t i = which[k];
    ASSERT_EQ(kept.pointsOf(k), from.pointsOf(i)) << "strand " << k;
    EXPECT_EQ(kept.firstPoint[k], point);
    for (uint32_t p = from.firstPoint[i]; p < from.firstPoint[i + 1]; ++p, ++point) {
      EXPECT_EQ(kept.points[point], from.points[p]);
      EXPECT_EQ(kept.tangents[point], from.tangents[p]);
      EXPECT_EQ(kept.normals[point], from.normals[p]);
      EXPECT_EQ(kept.colors[point], from.colors[p]);
      EXPECT_EQ(kept.thickness[point], from.thickness[p]);
      EXPECT_EQ(kept.transparency[point], from.transparency[p]);
    }
    EXPECT_EQ(kept.strandId[k], from.strandId[i]);
    EXPECT_EQ(kept.rootTriangle[k], from.rootTriangle[i]);
    EXPECT_EQ(kept.rootBary[k], from.rootBary[i]);
    EXPECT_EQ(kept.rootUv[k], from.rootUv[i]);
    EXPECT_EQ(kept.guideIds[k], from.guideIds[i]);
    EXPECT_EQ(kept.guideWeights[k], from.guideWeights[i]);
  }
  EXPECT_EQ(kept.pointCount(), point);
  EXPECT_EQ(kept.defaultThickness, from.defaultThickness);
  EXPECT_EQ(kept.defaultTransparency, from.defaultTransparency);
  EXPECT_EQ(kept.defaultColor, from.defaultColor);
  EXPECT_EQ(kept.provenance, from.provenance);
  EXPECT_TRUE(kept.simulationState.empty());  // a model's layout over every strand: not cut
}

TEST(Strands, KeepStrandsKeepsEveryArrayOfTheKeptStrandsInOrder) {
  const Strands s = withFollicles();
  std::vector<size_t> odd;
  for (size_t i = 1; i < s.strandCount(); i += 2) odd.push_back(i);
  expectStrandsOf(keepStrands(s, [](size_t i) { return i % 2 == 1; }), s, odd);
  expectStrandsOf(keepStrands(s, [](size_t) { return false; }), s, {});
}

TEST(Strands, KeepStrandsLeavesAbsentArraysAbsent) {
  Strands s = withFollicles();
  s.normals.clear();
  s.guideWeights.clear();
  const Strands kept = keepStrands(s, [](size_t i) { return i != 2; });
  EXPECT_TRUE(kept.normals.empty());
  EXPECT_TRUE(kept.guideWeights.empty());
  EXPECT_EQ(kept.colors.size(), kept.pointCount());
  EXPECT_EQ(kept.guideIds.size(), kept.strandCount());
}

TEST(Strands, WithoutOnePointStrandsKeepsTheOthersWhole) {
  const Strands s = withFollicles();
  std::vector<size_t> longer;
  for (size_t i = 0; i < s.strandCount(); ++i)
    if (s.pointsOf(i) >= 2) longer.push_back(i);
  EXPECT_EQ(onePointStrandCount(s), 4u);
  ASSERT_EQ(longer.size(), s.strandCount() - 4);
  const Strands kept = withoutOnePointStrands(s);
  expectStrandsOf(kept, s, longer);
  EXPECT_EQ(onePointStrandCount(kept), 0u);
}

}  // namespace
}  // namespace hairgen
