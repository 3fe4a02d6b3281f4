// hairgen diff A.exr B.exr: golden-image comparison with OpenImageIO's idiff thresholds. A pixel fails
// when any channel differs by more than --fail; the images fail when more than --failpercent percent
// of the pixels fail, or when any channel differs by more than --hardfail anywhere. Exit 4 then.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>

#include "cli/commands.h"
#include "cli/common.h"
#include "libcore/io/exr_io.h"
#include "libcore/util/error.h"

namespace hairgen::cli {
namespace {

struct ChannelStats {
  double sum = 0.0, sum2 = 0.0, max = 0.0;
};

std::string number(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.6g", v);
  return text;
}

}  // namespace

void registerDiff(CLI::App& app, int& exitCode) {
  struct Options {
    CommonOptions common;
    std::string a, b, out;
    double fail = 0.004, failPercent = 0.02, hardFail = 0.012;
    std::vector<std::string> channels;
  };
  auto options = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand("diff",
                                     "Compare two images channel by channel: mean, RMS and max error, the "
                                     "worst pixel, pass or fail (exit 4)");
  cmd->add_option("A", options->a, "The reference image (any format OpenImageIO reads)")->required();
  cmd->add_option("B", options->b, "The image to check")->required();
  cmd->add_option("--fail", options->fail, "A pixel fails when a channel differs by more than this")
      ->default_val(0.004);
  cmd->add_option("--failpercent", options->failPercent,
                  "The images fail when more than this percent of pixels fail")
      ->default_val(0.02);
  cmd->add_option("--hardfail", options->hardFail,
                  "The images fail when any channel anywhere differs by more than this")
      ->default_val(0.012);
  cmd->add_option("--channels", options->channels, "Compare only these channels (default: all)")
      ->delimiter(',');
  cmd->add_option("--out", options->out, "Write |A - B| per channel")->type_name("DIFF.exr");
  cmd->add_flag("--quiet,-q", options->common.quiet, "Print only the verdict");
  cmd->footer(exitCodeHelp());
  cmd->callback([options, &exitCode] {
    exitCode = runCommand("diff", options->common, [&] {
      Image a = readImage(options->a), b = readImage(options->b);
      bool passed = true;
      auto verdict = [&](bool pass, const std::string& why) {
        std::cout << (pass ? "PASS" : "FAIL") << (why.empty() ? "" : ": " + why) << "\n";
        passed = pass;
      };
      if (a.width != b.width || a.height != b.height) {
        verdict(false, "sizes differ: " + std::to_string(a.width) + "x" + std::to_string(a.height) + " and " +
                           std::to_string(b.width) + "x" + std::to_string(b.height));
        throw ExitWith{ExitCode::kDiffFailed};
      }
      std::vector<std::string> names = options->channels.empty() ? a.channels : options->channels;
      for (const std::string& n : names) {
        bool inA = std::find(a.channels.begin(), a.channels.end(), n) != a.channels.end();
        bool inB = std::find(b.channels.begin(), b.channels.end(), n) != b.channels.end();
        if (!inA && !options->channels.empty())
          throw InputError({options->a, 0}, "has no channel '" + n + "'");
        if (!inB) {
          verdict(false, "channel " + n + " is missing from " + options->b);
          throw ExitWith{ExitCode::kDiffFailed};
        }
      }
      const size_t pixels = size_t(a.width) * a.height;
      std::vector<ChannelStats> stats(names.size());
      std::vector<char> failing(pixels, 0);
      double worst = -1.0;
      size_t worstPixel = 0, worstChannel = 0;
      Image difference;
      difference.width = a.width;
      difference.height = a.height;
      for (size_t c = 0; c < names.size(); ++c) {
        const std::vector<float>& pa = a.plane(names[c]);
        const std::vector<float>& pb = b.plane(names[c]);
        std::vector<float> d(pixels);
        for (size_t i = 0; i < pixels; ++i) {
          double e = std::abs(double(pa[i]) - double(pb[i]));
          if (std::isnan(e)) e = std::isnan(pa[i]) && std::isnan(pb[i]) ? 0.0 : HUGE_VAL;
          d[i] = static_cast<float>(e);
          stats[c].sum += e;
          stats[c].sum2 += e * e;
          stats[c].max = std::max(stats[c].max, e);
          if (e > options->fail) failing[i] = 1;
          if (e > worst) worst = e, worstPixel = i, worstChannel = c;
        }
        difference.channels.push_back(names[c]);
        difference.planes.push_back(std::move(d));
      }
      size_t failed = 0;
      for (char f : failing) failed += f;
      const double failedPercent = pixels ? 100.0 * double(failed) / double(pixels) : 0.0;
      if (!options->common.quiet) {
        std::cout << "comparing " << options->a << " and " << options->b << ": " << a.width << "x" << a.height
                  << ", " << names.size() << " channels\n";
        for (size_t c = 0; c < names.size(); ++c)
          std::cout << "  " << names[c] << ": mean " << number(stats[c].sum / double(pixels)) << "  RMS "
                    << number(std::sqrt(stats[c].sum2 / double(pixels))) << "  max " << number(stats[c].max)
                    << "\n";
        if (worst > 0.0) {
          int x = int(worstPixel % size_t(a.width)), y = int(worstPixel / size_t(a.width));
          const std::string& n = names[worstChannel];
          std::cout << "  worst pixel (" << x << ", " << y << ") channel " << n << ": "
                    << number(a.plane(n)[worstPixel]) << " vs " << number(b.plane(n)[worstPixel]) << "\n";
        }
        std::cout << "  " << failed << " pixels (" << number(failedPercent) << "%) differ by more than "
                  << number(options->fail) << "\n";
      }
      if (!options->out.empty()) writeExr(options->out, difference, {});
      if (worst > options->hardFail)
        verdict(false,
                "a difference of " + number(worst) + " is beyond --hardfail " + number(options->hardFail));
      else if (failedPercent > options->failPercent)
        verdict(false, number(failedPercent) + "% of pixels are beyond --fail " + number(options->fail) +
                           ", more than --failpercent " + number(options->failPercent));
      else
        verdict(true, "");
      if (!passed) throw ExitWith{ExitCode::kDiffFailed};
    });
  });
}

}  // namespace hairgen::cli
