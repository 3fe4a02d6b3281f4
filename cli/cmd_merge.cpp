// hairgen merge PARTS... -o WHOLE: the shards of grow or interpolate --shard K/N joined into the file
// the whole run writes, byte for byte.
#include "cli/commands.h"
#include "cli/common.h"
#include "libcore/io/hair_cache.h"
#include "libcore/model/shards.h"

namespace hairgen::cli {

void registerMerge(CLI::App& app, int& exitCode) {
  struct Options {
    CommonOptions common;
    std::vector<std::string> parts;
    std::string output;
  };
  auto options = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand(
      "merge",
      "Join the shards of `grow --shard K/N` or `interpolate --shard K/N` into the file the whole run "
      "writes, "
      "byte for byte; refuses (exit 2, naming the part) a part from another config, stage or split, an "
      "overlapping part or a missing range");
  cmd->add_option("PARTS", options->parts, "The shards, in any order (.hair)")->required();
  cmd->add_option("-o,--output", options->output, "The whole file to write (written atomically)")
      ->type_name("FILE")
      ->required();
  addCommonFlags(*cmd, options->common, false);
  cmd->callback([options, &exitCode] {
    exitCode = runCommand("merge", options->common, [&] {
      Stats stats("merge");
      hairFormatOf(options->output);
      Stopwatch clock;
      std::vector<ShardPart> parts;
      for (const std::string& name : options->parts) parts.push_back({name, readStrands(name)});
      stats.time("read", clock.lap());
      const Strands whole = mergeShards(std::move(parts));
      stats.time("merge", clock.lap());
      writeStrands(options->output, whole);
      stats.time("write", clock.lap());
      stats.counts()["parts"] = options->parts.size();
      stats.counts()["strands"] = whole.strandCount();
      note(options->common, "merge: " + std::to_string(options->parts.size()) + " shards, " +
                                std::to_string(whole.strandCount()) + " strands, wrote " + options->output);
      stats.write(options->common);
    });
  });
}

}  // namespace hairgen::cli
