// hairgen diff's comparison: idiff's three thresholds and the NaN rule.
#include <gtest/gtest.h>

#include <cmath>

#include "libcore/io/image_diff.h"

namespace hairgen {
namespace {

Image flat(int w, int h, float value) {
  Image image;
  image.width = w;
  image.height = h;
  for (const char* c : {"R", "G"}) {
    image.channels.push_back(c);
    image.planes.emplace_back(size_t(w) * h, value);
  }
  return image;
}

TEST(ImageDiff, EqualImagesPass) {
  ImageDiff d = diffImages(flat(10, 10, 0.5f), flat(10, 10, 0.5f), {}, {}, "a.exr");
  EXPECT_EQ(d.code, ExitCode::kSuccess);
  EXPECT_EQ(d.worst, 0.0);
  EXPECT_EQ(d.failingPixels, 0u);
  ASSERT_EQ(d.channels.size(), 2u);
  EXPECT_EQ(d.channels[1].name, "G");
}

TEST(ImageDiff, FailPercentCountsPixelsOnceWhateverTheirChannels) {
  Image a = flat(10, 10, 0.5f), b = a;
  b.planes[0][7] += 0.006f;  // one pixel of 100, in two channels: 1% of the pixels
  b.planes[1][7] += 0.006f;
  ImageDiff d = diffImages(a, b, {}, {}, "a.exr");
  EXPECT_EQ(d.failingPixels, 1u);
  EXPECT_EQ(d.code, ExitCode::kDiffFailed);  // 1% > 0.02%
  EXPECT_EQ(d.worstX, 7);
  EXPECT_EQ(d.worstY, 0);
  EXPECT_NEAR(d.channels[0].mean, 0.006 / 100.0, 1e-6);
  DiffThresholds lenient;
  lenient.failPercent = 2.0;
  EXPECT_EQ(diffImages(a, b, {}, lenient, "a.exr").code, ExitCode::kSuccess);
}

TEST(ImageDiff, HardFailCatchesOneLargeDifference) {
  Image a = flat(10, 10, 0.5f), b = a;
  b.planes[1][42] = 0.52f;
  DiffThresholds lenient;
  lenient.failPercent = 50.0;
  ImageDiff d = diffImages(a, b, {}, lenient, "a.exr");
  EXPECT_EQ(d.code, ExitCode::kDiffFailed);
  EXPECT_NE(d.reason.find("--hardfail"), std::string::npos);
  EXPECT_EQ(d.worstChannel, "G");
  EXPECT_EQ(d.worstX, 2);
  EXPECT_EQ(d.worstY, 4);
  EXPECT_FLOAT_EQ(d.worstB, 0.52f);
}

TEST(ImageDiff, ANanInBothImagesIsEqualAndInOneIsInfinitelyDifferent) {
  Image a = flat(4, 4, 0.5f), b = a;
  a.planes[0][3] = b.planes[0][3] = NAN;
  EXPECT_EQ(diffImages(a, b, {}, {}, "a.exr").code, ExitCode::kSuccess);
  b.planes[0][5] = NAN;
  ImageDiff d = diffImages(a, b, {}, {}, "a.exr");
  EXPECT_EQ(d.code, ExitCode::kDiffFailed);
  EXPECT_TRUE(std::isinf(d.worst));
  EXPECT_EQ(d.worstX, 1);
  EXPECT_EQ(d.worstY, 1);
  EXPECT_TRUE(std::isinf(d.difference.planes[0][5]));
  EXPECT_EQ(d.difference.planes[0][3], 0.0f);
}

TEST(ImageDiff, ShapesAndChannelsThatDoNotMatch) {
  EXPECT_EQ(diffImages(flat(4, 4, 0), flat(4, 5, 0), {}, {}, "a.exr").code, ExitCode::kDiffFailed);
  Image b = flat(4, 4, 0);
  b.channels[1] = "B";
  ImageDiff d = diffImages(flat(4, 4, 0), b, {}, {}, "a.exr");
  EXPECT_EQ(d.code, ExitCode::kDiffFailed);
  EXPECT_NE(d.reason.find("channel G"), std::string::npos);
  EXPECT_EQ(diffImages(flat(4, 4, 0), b, {"R"}, {}, "a.exr").code, ExitCode::kSuccess);
  EXPECT_THROW(diffImages(flat(4, 4, 0), b, {"Z"}, {}, "a.exr"), InputError);
}

}  // namespace
}  // namespace hairgen
