// Registration of the hairgen subcommands. Each registers its options and a callback that runs the
// command and stores its exit code. The *Stage functions are the stage bodies `run` shares with the
// single-stage commands, so both give the same files.
#pragma once

#include <future>
#include <optional>
#include <string>

#include <CLI/CLI.hpp>

#include "cli/common.h"
#include "libcore/config/params.h"
#include "libcore/model/mesh.h"
#include "libcore/model/strands.h"
#include "stages/grow.h"
#include "stages/render.h"
#include "stages/shade.h"

namespace hairgen::cli {

void registerInfo(CLI::App& app, int& exitCode);
void registerConvert(CLI::App& app, int& exitCode);
void registerCheck(CLI::App& app, int& exitCode);
void registerAssets(CLI::App& app, int& exitCode);
void registerGrow(CLI::App& app, int& exitCode);
void registerInterpolate(CLI::App& app, int& exitCode);
void registerRun(CLI::App& app, int& exitCode);
void registerRender(CLI::App& app, int& exitCode);
void registerShade(CLI::App& app, int& exitCode);
void registerSimulate(CLI::App& app, int& exitCode);
void registerDiff(CLI::App& app, int& exitCode);

void registerMerge(CLI::App& app, int& exitCode);
void registerFarm(CLI::App& app, int& exitCode);
void registerMovie(CLI::App& app, int& exitCode);

// `shard`: only that range of the work (--shard K/N); none for the whole.
GrowResult growStage(const CommonOptions& common, const Config& config, const Mesh& wick, Stats& stats,
                     std::optional<ShardRange> shard = {});
Strands interpolateStage(const CommonOptions& common, const Config& config, const Mesh& wick,
                         const Strands& guides, const std::string& guidesName, Stats& stats,
                         std::optional<ShardRange> shard = {});
// `volumeWritten`: the volume is written out (--vdb), so its distance is computed at every node.
ShadeResult shadeStage(const CommonOptions& common, const Config& config, Strands coupe, Stats& stats,
                       bool volumeWritten = false);
// Opens the device, reads the Setup's custom shader files and calls the render stage; records the
// device and the passes' times in `stats`.
// Opens the rendering device (once per command) and names it on stderr; with `opening`
// (GlContext::openInBackground, started before the inputs were read), waits for that one instead and
// makes it current here. Records the wait as the phase "device" and what the start cost in the JSON's
// device.start (seconds: finding devices, the display's initialisation, the context's creation).
std::unique_ptr<GlContext> openDevice(const CommonOptions& common, const Config& config, Stats& stats,
                                      std::future<std::unique_ptr<GlContext>>* opening = nullptr);
RenderOutput renderStage(const CommonOptions& common, const Config& config, GlContext& gl,
                         const Strands& hair, const Mesh* head, const RenderOptions& options, Stats& stats,
                         const FrameBefore* before = nullptr);
// Writes the EXR, and the light's maps and the preview where named (empty: not wanted). A sequence's
// `frame` goes into the EXRs' headers (hairgen:frame) with Dynamics FrameRate as framesPerSecond.
void writeRenderOutputs(const Config& config, const RenderOutput& out, const std::string& exr,
                        const std::string& dom, const std::string& preview,
                        std::optional<int> frame = std::nullopt);

}  // namespace hairgen::cli
