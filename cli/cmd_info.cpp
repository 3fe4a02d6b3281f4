// hairgen info FILE [--json]: what a .hair/.gltf/.glb/.obj holds.
#include <iostream>

#include "cli/commands.h"
#include "cli/common.h"
#include "libcore/io/hair_cache.h"
#include "libcore/io/info.h"
#include "libcore/util/json.h"

namespace hairgen::cli {

void registerInfo(CLI::App& app, int& exitCode) {
  struct Options {
    CommonOptions common;
    std::string file;
    bool json = false;
  };
  auto options = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand("info", "Describe a file (" + hairExtensionList() +
                                                 ", .obj, .exr): counts, bounds, attributes, provenance");
  cmd->add_option("FILE", options->file, "The file to describe")->required();
  cmd->add_flag("--json", options->json, "Print the description as JSON");
  addCommonFlags(*cmd, options->common, false);
  cmd->callback([options, &exitCode] {
    exitCode = runCommand("info", options->common, [&] {
      Stats stats("info");
      nlohmann::ordered_json description = describeFile(options->file);
      std::cout << (options->json ? jsonText(description) + "\n" : formatDescription(description));
      stats.json()["file"] = description;
      stats.write(options->common);
    });
  });
}

}  // namespace hairgen::cli
