// hairgen: grows, styles, caches and renders hair. This file only parses the command line and hands
// over to one command; everything else lives in libcore/ and stages/.
#include <algorithm>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "cli/commands.h"
#include "cli/common.h"
#include "libcore/util/text.h"

namespace {

// A first word that is no command (a typo): named, with the nearest command, rather than CLI11's "A
// subcommand is required". True when `word` was refused.
bool refuseUnknownCommand(const CLI::App& app, const std::string& word) {
  if (word.empty() || word[0] == '-') return false;
  std::vector<std::string> names;
  for (const CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; }))
    names.push_back(sub->get_name());
  if (std::find(names.begin(), names.end(), word) != names.end()) return false;
  const std::string close = hairgen::closestMatch(word, names);
  std::string all;
  for (const std::string& n : names) all += (all.empty() ? "" : ", ") + n;
  std::cerr << "hairgen: error: unknown command '" << word << "'"
            << (close.empty() ? "; the commands are " + all : "; did you mean '" + close + "'?") << "\n"
            << "Run 'hairgen --help' for usage.\n";
  return true;
}

}  // namespace

// Where a --set's value was split by the shell (`--set Render.Resolution=320 320`: CLI11 sees 320 as an
// argument it did not expect) or given without '=', what to write instead; empty otherwise.
std::string setHint(const std::string& error, int argc, char** argv) {
  for (int k = 1; k + 2 < argc; ++k) {
    if (std::string(argv[k]) != "--set") continue;
    const std::string value = argv[k + 1], next = argv[k + 2];
    if (next.empty() || next[0] == '-' || error.find("not expected: " + next) == std::string::npos) continue;
    if (value.find('=') == std::string::npos)
      return " (--set takes KEY=VALUE as one argument: --set '" + value + "=" + next + "')";
    return " (a --set value with spaces is one argument: quote it, --set '" + value + " " + next + "')";
  }
  return "";
}

int main(int argc, char** argv) {
  using namespace hairgen::cli;
  CLI::App app{
      "hairgen " HAIRGEN_VERSION
      ": grows, styles, simulates, caches and renders hair for CG characters: Super-Helix guides, "
      "interpolation, Anjyo's cantilever styling, dynamics (a shot's guides simulated frame by frame with "
      "Anjyo's model or mass springs, under a moving head), hair shading (Kajiya-Kay, the thesis's, "
      "Anjyo's, volumetric) with deep opacity maps, and a shot's work split into tasks for a render farm "
      "(farm plan, farm submit to Slurm).",
      "hairgen"};
  app.footer(exitCodeHelp());
  app.formatter(std::make_shared<HelpFormatter>());
  app.require_subcommand(1);
  app.set_version_flag("--version", "hairgen " HAIRGEN_VERSION);

  int exitCode = 0;
  registerRun(app, exitCode);
  registerGrow(app, exitCode);
  registerInterpolate(app, exitCode);
  registerSimulate(app, exitCode);
  registerShade(app, exitCode);
  registerRender(app, exitCode);
  registerMerge(app, exitCode);
  registerFarm(app, exitCode);
  registerMovie(app, exitCode);
  registerDiff(app, exitCode);
  registerInfo(app, exitCode);
  registerConvert(app, exitCode);
  registerCheck(app, exitCode);
  registerAssets(app, exitCode);
  pointAtExitCodes(app);

  if (argc > 1 && refuseUnknownCommand(app, argv[1])) return 2;
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::RuntimeError& e) {  // a standalone flag's job ended (addStandaloneFlag)
    return e.get_exit_code();
  } catch (const CLI::ParseError& e) {
    std::string where = "hairgen";
    for (const CLI::App* sub : app.get_subcommands()) where += " " + sub->get_name();
    // One line, as every error: what is wrong, a hint where a --set value was split by the shell, and
    // where the usage is.
    std::cerr << where << ": error: " << e.what() << setHint(e.what(), argc, argv) << "; run '" << where
              << " --help' for usage\n";
    return 2;
  }
  return exitCode;
}
