// hairgen diff A.exr B.exr: golden-image comparison with OpenImageIO's idiff thresholds (exit 4 when the
// images fail them); the comparison itself is diffImages() in libcore/io/image_diff.h.
// hairgen diff A.hair B.hair: the same for two hair caches, point by point within a distance
// (diffHair() in libcore/io/hair_diff.h).
#include <iostream>
#include <optional>

#include "cli/commands.h"
#include "cli/common.h"
#include "libcore/io/exr_io.h"
#include "libcore/io/hair_diff.h"
#include "libcore/io/image_diff.h"

namespace hairgen::cli {
namespace {

std::string number(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.6g", v);
  return text;
}

void printReport(const std::string& a, const std::string& b, const ImageDiff& d, const DiffThresholds& t) {
  std::cout << "comparing " << a << " and " << b << ": " << d.width << "x" << d.height << ", "
            << d.channels.size() << " channels\n";
  for (const ChannelDiff& c : d.channels)
    std::cout << "  " << c.name << ": mean " << number(c.mean) << "  RMS " << number(c.rms) << "  max "
              << number(c.max) << "\n";
  if (d.worst > 0.0)
    std::cout << "  worst pixel (" << d.worstX << ", " << d.worstY << ") channel " << d.worstChannel << ": "
              << number(d.worstA) << " vs " << number(d.worstB) << "\n";
  std::cout << "  " << d.failingPixels << " pixels (" << number(d.failingPercent) << "%) differ by more than "
            << number(t.fail) << "\n";
}

void printReport(const std::string& a, const std::string& b, const HairDiff& d) {
  std::cout << "comparing " << a << " and " << b << ": " << d.strands << " strands, " << d.points
            << " points\n";
  if (!d.structureMatches) return;
  std::cout << "  points: mean " << number(d.meanDistance) << " m  max " << number(d.maxDistance) << " m";
  if (d.maxDistance > 0.0) std::cout << " (strand " << d.worstStrand << ", point " << d.worstPoint << ")";
  std::cout << "\n";
  if (d.normalsCompared) std::cout << "  normals: max " << number(d.maxAngleDegrees) << " degrees\n";
  if (d.colorsCompared) std::cout << "  colours: max " << number(d.maxColor) << "\n";
}

struct DiffArgs {
  CommonOptions common;
  std::string a, b, out, sheet;
  DiffThresholds thresholds;
  std::vector<std::string> channels;
  HairDiffTolerances tolerances;
  std::vector<const CLI::Option*> imageFlags, cacheFlags;  // to refuse one kind's flags on the other
};

// Whether `file` names a hair cache rather than an image; a hair format hairgen only writes is refused.
bool isCache(const std::string& file) {
  const std::optional<HairFormat> format = hairFormatFor(file);
  if (format && !hairgenReads(*format))
    throw InputError({file, 0}, std::string("diff reads hair caches (") + readHairExtensionList() +
                                    ") and images; hairgen writes " + describe(*format) +
                                    " but does not read it");
  return format.has_value();
}

// Either two hair caches or two images; a flag of the other kind is a usage error.
bool comparesCaches(const DiffArgs& options) {
  const bool a = isCache(options.a), b = isCache(options.b);
  if (a != b)
    throw InputError((a ? options.a : options.b) + " is a hair cache and " + (a ? options.b : options.a) +
                     " is not; compare two images or two caches (" + readHairExtensionList() + ")");
  for (const CLI::Option* flag : a ? options.imageFlags : options.cacheFlags)
    if (flag->count() > 0)
      throw InputError(flag->get_name() + " applies to " + (a ? "images" : "hair caches") + ", not to " +
                       (a ? "hair caches" : "images"));
  return a;
}

ExitCode compareCaches(const DiffArgs& options, Stats& stats) {
  const Strands a = readStrands(options.a), b = readStrands(options.b);
  const HairDiff d = diffHair(a, b, options.tolerances);
  if (!options.common.quiet) printReport(options.a, options.b, d);
  std::cout << (d.code == ExitCode::kSuccess ? "PASS" : "FAIL: " + d.reason) << "\n";
  stats.json()["maxDistance"] = d.maxDistance;
  stats.json()["passed"] = d.code == ExitCode::kSuccess;
  return d.code;
}

ExitCode compareImages(const DiffArgs& options, Stats& stats) {
  const Image a = readImage(options.a), b = readImage(options.b);
  const ImageDiff d = diffImages(a, b, options.channels, options.thresholds, options.a);
  if (!options.common.quiet && !d.channels.empty()) printReport(options.a, options.b, d, options.thresholds);
  if (!options.out.empty() && !d.difference.planes.empty()) writeExr(options.out, d.difference, {});
  if (!options.sheet.empty() && !d.difference.planes.empty()) writeComparisonSheet(options.sheet, a, b, d);
  std::cout << (d.code == ExitCode::kSuccess ? "PASS" : "FAIL: " + d.reason) << "\n";
  stats.counts()["failingPixels"] = d.failingPixels;
  stats.json()["worst"] = d.worst;
  stats.json()["passed"] = d.code == ExitCode::kSuccess;
  return d.code;
}

}  // namespace

void registerDiff(CLI::App& app, int& exitCode) {
  auto options = std::make_shared<DiffArgs>();
  CLI::App* cmd = app.add_subcommand(
      "diff",
      "Compare two images channel by channel (mean, RMS and max error, the worst pixel) or two hair caches "
      "point by point (mean and max distance, normals, colours): pass, or fail with exit 4");
  cmd->add_option("A", options->a,
                  "The reference: an image (any format OpenImageIO reads) or a hair cache (" +
                      readHairExtensionList() + ")")
      ->required();
  cmd->add_option("B", options->b, "The image or cache to check")->required();
  auto& image = options->imageFlags;
  image.push_back(cmd->add_option("--fail", options->thresholds.fail,
                                  "Images: a pixel fails when a channel differs by more than this (>= 0)")
                      ->type_name("X")
                      ->capture_default_str()
                      ->check(kFiniteNonNegative));
  image.push_back(cmd->add_option("--failpercent", options->thresholds.failPercent,
                                  "Images: they fail when more than this percent of pixels fail (0 to 100)")
                      ->type_name("PERCENT")
                      ->capture_default_str()
                      ->check(kFiniteNonNegative & CLI::Range(0.0, 100.0)));
  image.push_back(
      cmd->add_option("--hardfail", options->thresholds.hardFail,
                      "Images: they fail when any channel anywhere differs by more than this (>= 0)")
          ->type_name("X")
          ->capture_default_str()
          ->check(kFiniteNonNegative));
  image.push_back(cmd->add_option("--channels", options->channels,
                                  "Images: compare only these channels (default: all of A's)")
                      ->type_name("NAME")
                      ->delimiter(','));
  image.push_back(
      cmd->add_option("--out", options->out, "Images: write |A - B| per channel")->type_name("DIFF.exr"));
  image.push_back(
      cmd->add_option("--sheet", options->sheet,
                      "Images: write A, B and 10 x |A - B| side by side as one sRGB picture, to look at")
          ->type_name("FILE.png"));
  options->cacheFlags.push_back(
      cmd->add_option("--tolerance", options->tolerances.distance,
                      "Caches: they fail when a point lies farther than this from the reference's (metres; "
                      "strand count, points per strand and roots must match exactly)")
          ->type_name("METRES")
          ->capture_default_str()
          ->check(kFiniteNonNegative));
  options->cacheFlags.push_back(
      cmd->add_option("--angle-tolerance", options->tolerances.angleDegrees,
                      "Caches: they fail when a normal turns by more than this (degrees)")
          ->type_name("DEGREES")
          ->capture_default_str()
          ->check(kFiniteNonNegative));
  addCommonFlags(*cmd, options->common, false);
  cmd->callback([options, &exitCode] {
    ExitCode verdict = ExitCode::kSuccess;
    exitCode = runCommand("diff", options->common, [&] {
      Stats stats("diff");
      verdict = comparesCaches(*options) ? compareCaches(*options, stats) : compareImages(*options, stats);
      stats.write(options->common);
    });
    if (exitCode == 0) exitCode = static_cast<int>(verdict);
  });
}

}  // namespace hairgen::cli
