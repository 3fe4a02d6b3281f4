// hairgen convert IN OUT: between .hair, .gltf, .glb, .ply and .data, and to .usda, keeping every
// attribute both formats carry; --units and --up-axis bring a file made elsewhere to metres, +y up.
#include "cli/commands.h"
#include "cli/common.h"
#include "libcore/io/hair_cache.h"

namespace hairgen::cli {

void registerConvert(CLI::App& app, int& exitCode) {
  struct Options {
    CommonOptions common;
    UnitOptions units;
    std::string input, output;
    bool ascii = false;
  };
  auto options = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand(
      "convert",
      "Convert strands between .hair, .gltf, .glb, .ply and .data, or export them to .usda (format from the "
      "extension)");
  cmd->add_option("IN", options->input, "Input .hair, .gltf, .glb, .ply or .data")->required();
  cmd->add_option("OUT", options->output,
                  "Output .hair, .gltf, .glb, .ply, .data or .usda (written atomically)")
      ->required();
  addUnitFlags(*cmd, options->units, "IN");
  cmd->add_flag("--ascii", options->ascii, "Write a .ply as ASCII text instead of binary little-endian");
  addCommonFlags(*cmd, options->common, false);
  cmd->callback([options, &exitCode] {
    exitCode = runCommand("convert", options->common, [&] {
      Stats stats("convert");
      if (options->ascii && hairFormatOf(options->output) != HairFormat::kPly)
        throw InputError("--ascii is for a .ply output; " + options->output + " is " +
                         describe(hairFormatOf(options->output)));
      hairFormatOf(options->output);  // reject a bad extension before reading anything
      Stopwatch clock;
      Strands strands = readStrandsAs(options->input, options->units);
      // A file made elsewhere: this conversion is its hairgen provenance, with the source's name.
      if (strands.provenance.producer.empty()) {
        strands.provenance.producer = "hairgen " HAIRGEN_VERSION;
        strands.provenance.stage = "convert";
      }
      stats.time("read", clock.lap());
      writeStrands(options->output, strands, WriteOptions{options->ascii});
      stats.time("write", clock.lap());
      stats.counts()["strands"] = strands.strandCount();
      stats.counts()["points"] = strands.pointCount();
      note(options->common, "wrote " + options->output + " (" + std::to_string(strands.strandCount()) +
                                " strands, " + std::to_string(strands.pointCount()) + " points" +
                                (strands.provenance.metres && strands.provenance.yUp
                                     ? ""
                                     : "; units or up axis unknown: give --units and --up-axis") +
                                ")");
      stats.write(options->common);
    });
  });
}

}  // namespace hairgen::cli
