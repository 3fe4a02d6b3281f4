// Golden-image comparison as OpenImageIO's idiff does it (the statistics of ImageBufAlgo::compare,
// computed here), with its thresholds:
// a pixel fails when any channel differs by more than `fail`; the images fail when more than
// `failPercent` percent of the pixels fail, or when any channel anywhere differs by more than
// `hardFail`. NaN rule: a NaN in both images at the same place is equal; a NaN (or an infinity) in only
// one of them, or infinities of different sign, is an infinite difference.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "libcore/model/image.h"
#include "libcore/util/error.h"

namespace hairgen {

// idiff's defaults (OpenImageIO's testsuite uses the same three).
struct DiffThresholds {
  double fail = 0.004;
  double failPercent = 0.02;  // percent of the pixels
  double hardFail = 0.012;
};

struct ChannelDiff {
  std::string name;
  double mean = 0.0, rms = 0.0, max = 0.0;  // of |A − B|
};

struct ImageDiff {
  int width = 0, height = 0;
  std::vector<ChannelDiff> channels;
  size_t failingPixels = 0;  // pixels where some channel differs by more than `fail`
  double failingPercent = 0.0;
  // The largest difference (0 when the images are equal): where, which channel, and both values.
  double worst = 0.0;
  int worstX = 0, worstY = 0;
  std::string worstChannel;
  float worstA = 0.0f, worstB = 0.0f;
  Image difference;    // |A − B| per compared channel (infinite where only one image holds a NaN)
  std::string reason;  // why the images fail; empty when they pass
  ExitCode code = ExitCode::kSuccess;  // kSuccess, or kDiffFailed
};

// Compares `channels` of A and B (every channel of A when empty). Images of different sizes, or a
// channel that B lacks, fail (kDiffFailed with the reason); a channel asked for that A lacks is an
// InputError naming `nameA`.
ImageDiff diffImages(const Image& a, const Image& b, const std::vector<std::string>& channels,
                     const DiffThresholds& thresholds, const std::string& nameA);

// The reference, the image and their difference side by side in one sRGB PNG, for a person to look at
// when a golden case fails: R G B of A | R G B of B | |A − B| of R G B scaled by `gain`.
void writeComparisonSheet(const std::filesystem::path& file, const Image& a, const Image& b,
                          const ImageDiff& diff, double gain = 10.0);

}  // namespace hairgen
