// Registration of the hairgen subcommands. Each registers its options and a callback that runs the
// command and stores its exit code.
#pragma once

#include <CLI/CLI.hpp>

namespace hairgen::cli {

void registerInfo(CLI::App& app, int& exitCode);
void registerConvert(CLI::App& app, int& exitCode);
void registerCheck(CLI::App& app, int& exitCode);
void registerAssets(CLI::App& app, int& exitCode);
void registerGrow(CLI::App& app, int& exitCode);

}  // namespace hairgen::cli
