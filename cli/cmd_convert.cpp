// hairgen convert IN OUT: between .hair, .gltf and .glb, keeping every attribute both formats carry.
#include "cli/commands.h"
#include "cli/common.h"
#include "libcore/io/hair_cache.h"

namespace hairgen::cli {

void registerConvert(CLI::App& app, int& exitCode) {
  struct Options {
    CommonOptions common;
    std::string input, output;
  };
  auto options = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand(
      "convert", "Convert strands between .hair, .gltf and .glb (format from the extension)");
  cmd->add_option("IN", options->input, "Input .hair, .gltf or .glb")->required();
  cmd->add_option("OUT", options->output, "Output .hair, .gltf or .glb (written atomically)")->required();
  addCommonFlags(*cmd, options->common, false);
  cmd->footer(exitCodeHelp());
  cmd->callback([options, &exitCode] {
    exitCode = runCommand("convert", options->common, [&] {
      Stats stats("convert");
      hairFormatOf(options->output);  // reject a bad extension before reading anything
      Stopwatch clock;
      Strands strands = readStrands(options->input);
      stats.time("read", clock.lap());
      writeStrands(options->output, strands);
      stats.time("write", clock.lap());
      stats.counts()["strands"] = strands.strandCount();
      stats.counts()["points"] = strands.pointCount();
      note(options->common, "wrote " + options->output + " (" + std::to_string(strands.strandCount()) +
                                " strands, " + std::to_string(strands.pointCount()) + " points)");
      stats.write(options->common);
    });
  });
}

}  // namespace hairgen::cli
