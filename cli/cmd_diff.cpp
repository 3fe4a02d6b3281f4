// hairgen diff A.exr B.exr: golden-image comparison with OpenImageIO's idiff thresholds (exit 4 when the
// images fail them); the comparison itself is diffImages() in libcore/io/image_diff.h.
#include <iostream>

#include "cli/commands.h"
#include "cli/common.h"
#include "libcore/io/exr_io.h"
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

}  // namespace

void registerDiff(CLI::App& app, int& exitCode) {
  struct Options {
    CommonOptions common;
    std::string a, b, out, sheet;
    DiffThresholds thresholds;
    std::vector<std::string> channels;
  };
  auto options = std::make_shared<Options>();
  CLI::App* cmd =
      app.add_subcommand("diff",
                         "Compare two images channel by channel: mean, RMS and max error, the worst "
                         "pixel, pass or fail (exit 4)");
  cmd->add_option("A", options->a, "The reference image (any format OpenImageIO reads)")->required();
  cmd->add_option("B", options->b, "The image to check")->required();
  cmd->add_option("--fail", options->thresholds.fail,
                  "A pixel fails when a channel differs by more than this (>= 0)")
      ->type_name("X")
      ->capture_default_str()
      ->check(kFiniteNonNegative);
  cmd->add_option("--failpercent", options->thresholds.failPercent,
                  "The images fail when more than this percent of pixels fail (0 to 100)")
      ->type_name("PERCENT")
      ->capture_default_str()
      ->check(kFiniteNonNegative & CLI::Range(0.0, 100.0));
  cmd->add_option("--hardfail", options->thresholds.hardFail,
                  "The images fail when any channel anywhere differs by more than this (>= 0)")
      ->type_name("X")
      ->capture_default_str()
      ->check(kFiniteNonNegative);
  cmd->add_option("--channels", options->channels, "Compare only these channels (default: all of A's)")
      ->type_name("NAME")
      ->delimiter(',');
  cmd->add_option("--out", options->out, "Write |A - B| per channel")->type_name("DIFF.exr");
  cmd->add_option("--sheet", options->sheet,
                  "Write A, B and 10 x |A - B| side by side as one sRGB picture, to look at")
      ->type_name("FILE.png");
  addCommonFlags(*cmd, options->common, false);
  cmd->callback([options, &exitCode] {
    ExitCode verdict = ExitCode::kSuccess;
    exitCode = runCommand("diff", options->common, [&] {
      Stats stats("diff");
      const Image a = readImage(options->a), b = readImage(options->b);
      const ImageDiff d = diffImages(a, b, options->channels, options->thresholds, options->a);
      if (!options->common.quiet && !d.channels.empty())
        printReport(options->a, options->b, d, options->thresholds);
      if (!options->out.empty() && !d.difference.planes.empty()) writeExr(options->out, d.difference, {});
      if (!options->sheet.empty() && !d.difference.planes.empty())
        writeComparisonSheet(options->sheet, a, b, d);
      std::cout << (d.code == ExitCode::kSuccess ? "PASS" : "FAIL: " + d.reason) << "\n";
      stats.counts()["failingPixels"] = d.failingPixels;
      stats.json()["worst"] = d.worst;
      stats.json()["passed"] = d.code == ExitCode::kSuccess;
      stats.write(options->common);
      verdict = d.code;
    });
    if (exitCode == 0) exitCode = static_cast<int>(verdict);
  });
}

}  // namespace hairgen::cli
