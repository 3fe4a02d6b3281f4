#include "libcore/io/image_diff.h"

#include <algorithm>
#include <cmath>

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>

#include "libcore/io/exr_io.h"
#include "libcore/util/text.h"

namespace hairgen {
namespace {

std::string number(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.6g", v);
  return text;
}

// A channel pair ready for OpenImageIO: where both hold the same non-finite value the pair is (0, 0);
// where only one does, the pair is (0, 0) too and the pixel is recorded as infinitely different
// (compare() skips non-finite values rather than failing on them).
struct Prepared {
  std::vector<float> a, b;
  std::vector<size_t> infinite;  // pixels of this channel with a one-sided NaN or infinity
};

Prepared prepare(const std::vector<float>& a, const std::vector<float>& b) {
  Prepared p{a, b, {}};
  for (size_t i = 0; i < a.size(); ++i) {
    if (std::isfinite(a[i]) && std::isfinite(b[i])) continue;
    const bool same = (std::isnan(a[i]) && std::isnan(b[i])) || a[i] == b[i];
    if (!same) p.infinite.push_back(i);
    p.a[i] = p.b[i] = 0.0f;
  }
  return p;
}

OIIO::ImageBuf buffer(int width, int height, int channels, const float* data) {
  OIIO::ImageBuf buf(OIIO::ImageSpec(width, height, channels, OIIO::TypeDesc::FLOAT));
  buf.set_pixels(OIIO::ROI::All(), OIIO::TypeDesc::FLOAT, data);
  return buf;
}

}  // namespace

ImageDiff diffImages(const Image& a, const Image& b, const std::vector<std::string>& channels,
                     const DiffThresholds& thresholds, const std::string& nameA) {
  ImageDiff diff;
  diff.width = a.width;
  diff.height = a.height;
  auto fail = [&](const std::string& reason) {
    diff.reason = reason;
    diff.code = ExitCode::kDiffFailed;
    return diff;
  };
  if (a.width != b.width || a.height != b.height)
    return fail("sizes differ: " + std::to_string(a.width) + "x" + std::to_string(a.height) + " and " +
                std::to_string(b.width) + "x" + std::to_string(b.height));
  const std::vector<std::string> names = channels.empty() ? a.channels : channels;
  for (const std::string& n : names) {
    if (!a.has(n)) throw InputError({nameA, 0}, "has no channel '" + n + "'");
    if (!b.has(n)) return fail("channel " + n + " is missing from the second image");
  }

  const size_t pixels = size_t(a.width) * size_t(a.height), nc = names.size();
  std::vector<float> interleavedA(pixels * nc), interleavedB(pixels * nc);
  std::vector<char> infinitePixel(pixels, 0);
  diff.difference.width = a.width;
  diff.difference.height = a.height;
  diff.worst = 0.0;
  for (size_t c = 0; c < nc; ++c) {
    const std::vector<float>& pa = a.plane(names[c]);
    const std::vector<float>& pb = b.plane(names[c]);
    const Prepared p = prepare(pa, pb);
    for (size_t i = 0; i < pixels; ++i) {
      interleavedA[i * nc + c] = p.a[i];
      interleavedB[i * nc + c] = p.b[i];
    }
    ChannelDiff stats{names[c]};
    OIIO::ImageBuf ca = buffer(a.width, a.height, 1, p.a.data()),
                   cb = buffer(a.width, a.height, 1, p.b.data());
    const OIIO::ImageBufAlgo::CompareResults r =
        OIIO::ImageBufAlgo::compare(ca, cb, float(thresholds.fail), float(thresholds.fail));
    stats.mean = r.meanerror;
    stats.rms = r.rms_error;
    stats.max = r.maxerror;
    int x = r.maxx, y = r.maxy;
    if (!p.infinite.empty()) {
      stats.mean = stats.rms = stats.max = HUGE_VAL;
      x = int(p.infinite.front() % size_t(a.width));
      y = int(p.infinite.front() / size_t(a.width));
      for (size_t i : p.infinite) infinitePixel[i] = 1;
    }
    if (stats.max > diff.worst) {
      diff.worst = stats.max;
      diff.worstX = x;
      diff.worstY = y;
      diff.worstChannel = names[c];
      diff.worstA = pa[size_t(y) * a.width + x];
      diff.worstB = pb[size_t(y) * a.width + x];
    }
    std::vector<float> d(pixels);
    for (size_t i = 0; i < pixels; ++i) d[i] = std::abs(p.a[i] - p.b[i]);
    for (size_t i : p.infinite) d[i] = HUGE_VALF;
    diff.difference.channels.push_back(names[c]);
    diff.difference.planes.push_back(std::move(d));
    diff.channels.push_back(stats);
  }

  // A pixel fails when any of its channels does: one comparison over all of them counts it once.
  OIIO::ImageBuf all = buffer(a.width, a.height, int(nc), interleavedA.data());
  OIIO::ImageBuf allB = buffer(a.width, a.height, int(nc), interleavedB.data());
  const OIIO::ImageBufAlgo::CompareResults r =
      OIIO::ImageBufAlgo::compare(all, allB, float(thresholds.fail), float(thresholds.fail));
  diff.failingPixels = size_t(r.nfail);
  for (char f : infinitePixel) diff.failingPixels += f;
  diff.failingPercent = pixels ? 100.0 * double(diff.failingPixels) / double(pixels) : 0.0;

  if (diff.worst > thresholds.hardFail)
    return fail("a difference of " + number(diff.worst) + " is beyond --hardfail " +
                number(thresholds.hardFail));
  if (diff.failingPercent > thresholds.failPercent)
    return fail(number(diff.failingPercent) + "% of pixels are beyond --fail " + number(thresholds.fail) +
                ", more than --failpercent " + number(thresholds.failPercent));
  return diff;
}

void writeComparisonSheet(const std::filesystem::path& file, const Image& a, const Image& b,
                          const ImageDiff& diff, double gain) {
  const int w = a.width, h = a.height;
  Image sheet;
  sheet.width = 3 * w;
  sheet.height = h;
  for (const char* channel : {"R", "G", "B"}) {
    // Images without the channel show their first one in grey.
    auto plane = [&](const Image& image) -> const std::vector<float>& {
      return image.has(channel) ? image.plane(channel) : image.planes.front();
    };
    const std::vector<float>& pa = plane(a);
    const std::vector<float>& pb = plane(b);
    const std::vector<float>& pd = plane(diff.difference);
    std::vector<float> row(size_t(sheet.width) * h);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const size_t i = size_t(y) * w + x, o = size_t(y) * sheet.width + x;
        row[o] = pa[i];
        row[o + w] = pb[i];
        row[o + 2 * w] = std::min(float(gain) * pd[i], 1.0f);
      }
    sheet.channels.push_back(channel);
    sheet.planes.push_back(std::move(row));
  }
  writePreview(file, sheet, glm::dvec3(0.0));  // differences and images as they are, over black
}

}  // namespace hairgen
