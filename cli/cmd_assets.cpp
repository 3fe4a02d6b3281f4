// hairgen assets -o DIR: regenerate the bundled head and wick meshes from their generator.
#include "cli/commands.h"
#include "cli/common.h"
#include "libcore/assets/head_generator.h"

namespace hairgen::cli {

void registerAssets(CLI::App& app, int& exitCode) {
  struct Options {
    CommonOptions common;
    std::string outputDir = "configs/assets";
  };
  auto options = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand(
      "assets",
      "Generate the bundled head.obj and wick.obj (fitted to the thesis' head ellipsoid) and assets.txt, "
      "the generator's parameters");
  cmd->add_option("-o,--output", options->outputDir, "Directory to write into")
      ->type_name("DIR")
      ->capture_default_str();
  addCommonFlags(*cmd, options->common, false);
  cmd->callback([options, &exitCode] {
    exitCode = runCommand("assets", options->common, [&] {
      Stats stats("assets");
      HeadAssetParams params;
      HeadAssets assets = generateHeadAssets(params);
      writeHeadAssets(options->outputDir, params, assets);
      stats.counts()["headVertices"] = assets.head.vertexCount();
      stats.counts()["headTriangles"] = assets.head.triangleCount();
      stats.counts()["wickVertices"] = assets.wick.vertexCount();
      stats.counts()["wickTriangles"] = assets.wick.triangleCount();
      note(options->common, "wrote " + options->outputDir + "/head.obj (" +
                                std::to_string(assets.head.triangleCount()) + " triangles) and wick.obj (" +
                                std::to_string(assets.wick.vertexCount()) + " follicles)");
      stats.write(options->common);
    });
  });
}

}  // namespace hairgen::cli
