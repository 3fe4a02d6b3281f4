#include "libcore/io/image_diff.h"

#include <algorithm>
#include <cmath>

#include "libcore/io/exr_io.h"
#include "libcore/util/text.h"

namespace hairgen {
namespace {

std::string number(double v) {
  return formatSignificant(v, 6);
}

// A channel pair ready to compare: where both hold the same non-finite value the pair is (0, 0); where
// only one does, the pair is (0, 0) too and the pixel is recorded as infinitely different.
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

// One channel's errors as OpenImageIO's compare (and so idiff) computes them: |a − b| of each float
// pair (subtracted in float), summed in double for the mean and RMS over every pixel, the largest and
// the first pixel (in scanline order) that has it.
struct ChannelErrors {
  double mean = 0.0, rms = 0.0, max = 0.0;
  int x = 0, y = 0;
};

ChannelErrors errorsOf(const Prepared& p, int width) {
  ChannelErrors e;
  double sum = 0.0, squares = 0.0;
  size_t worst = 0;
  for (size_t i = 0; i < p.a.size(); ++i) {
    const double d = std::abs(p.a[i] - p.b[i]);
    sum += d;
    squares += d * d;
    if (d > e.max) {
      e.max = d;
      worst = i;
    }
  }
  const double n = p.a.empty() ? 1.0 : double(p.a.size());
  e.mean = sum / n;
  e.rms = std::sqrt(squares / n);
  e.x = int(worst % size_t(width));
  e.y = int(worst / size_t(width));
  return e;
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
  // A pixel fails when any of its channels does, and counts once.
  std::vector<char> failing(pixels, 0);
  const float failThreshold = float(thresholds.fail);
  diff.difference.width = a.width;
  diff.difference.height = a.height;
  diff.worst = 0.0;
  for (size_t c = 0; c < nc; ++c) {
    const std::vector<float>& pa = a.plane(names[c]);
    const std::vector<float>& pb = b.plane(names[c]);
    const Prepared p = prepare(pa, pb);
    ChannelDiff stats{names[c]};
    const ChannelErrors r = errorsOf(p, a.width);
    stats.mean = r.mean;
    stats.rms = r.rms;
    stats.max = r.max;
    int x = r.x, y = r.y;
    if (!p.infinite.empty()) {
      stats.mean = stats.rms = stats.max = HUGE_VAL;
      x = int(p.infinite.front() % size_t(a.width));
      y = int(p.infinite.front() / size_t(a.width));
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
    for (size_t i = 0; i < pixels; ++i) {
      d[i] = std::abs(p.a[i] - p.b[i]);
      if (d[i] > failThreshold) failing[i] = 1;
    }
    for (size_t i : p.infinite) {
      d[i] = HUGE_VALF;
      failing[i] = 1;
    }
    diff.difference.channels.push_back(names[c]);
    diff.difference.planes.push_back(std::move(d));
    diff.channels.push_back(stats);
  }
  diff.failingPixels = size_t(std::count(failing.begin(), failing.end(), char(1)));
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
