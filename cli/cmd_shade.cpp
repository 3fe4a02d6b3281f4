// hairgen shade SETUP --hair FILE -o OUT [--vdb FILE.vdb]: volumetric shading normals (and Anjyo's
// per-strand ambient) into the cache.
// hairgen shade --rest REST IN -o OUT: the rest pose's normals re-posed onto a deformed coupe.
#include <filesystem>
#include <iomanip>
#include <sstream>

#include "cli/commands.h"
#include "cli/common.h"
#include "libcore/config/setup.h"
#include "libcore/io/hair_cache.h"
#include "libcore/io/vdb_io.h"
#include "libcore/util/file_util.h"
#include "libcore/util/frames.h"
#include "libcore/util/progress.h"
#include "libcore/util/text.h"
#include "stages/shade.h"

namespace hairgen::cli {

ShadeResult shadeStage(const CommonOptions& common, const Config& config, Strands coupe, Stats& stats,
                       bool volumeWritten) {
  ShadeResult result =
      shade(std::move(coupe), config.visuality, config.render,
            ShadeOptions{config.hairstyle.seed, config.digest(), common.force, volumeWritten});
  const Strands& shaded = result.coupe;
  const Grid& grid = result.volume.density;
  stats.add("volume", result.timings.volume);
  stats.add("normals", result.timings.normals);
  stats.counts()["strands"] = shaded.strandCount();
  stats.counts()["points"] = shaded.pointCount();
  stats.counts()["grid"] = {grid.size.x, grid.size.y, grid.size.z};
  stats.counts()["voxelSize"] = grid.voxel;
  stats.counts()["shellDensity"] = result.volume.iso;
  std::ostringstream line;
  line << "shade: " << grid.size.x << "×" << grid.size.y << "×" << grid.size.z << " grid (VoxelSize "
       << formatReal(grid.voxel) << "), shell at " << std::setprecision(3) << result.volume.iso
       << std::setprecision(6) << " points/voxel, normals on " << shaded.pointCount() << " vertices in "
       << formatSeconds(result.timings.volume + result.timings.normals);
  if (wantsAmbient(config.visuality))
    line << "; per-strand ambient from N(" << formatReal(config.visuality.ambientMean) << ", "
         << formatReal(config.visuality.ambientDeviation) << ")";
  note(common, line.str());
  return result;
}

namespace {

struct ShadeArgs {
  CommonOptions common;
  std::string first, hair, rest, output, vdb, frames;
  UnitOptions units;
};

// --rest: the rest coupe's normals carried onto a deformed coupe, or onto every frame of a sequence.
void reposeCoupes(const ShadeArgs& o, Stats& stats) {
  Stopwatch clock;
  if (!o.vdb.empty()) throw InputError("--vdb needs a volume, which --rest does not build");
  if (!o.hair.empty() && !o.first.empty())
    throw InputError("with --rest no Setup is read: give the deformed coupe once, as --hair or on its own");
  const std::string& coupeFile = o.hair.empty() ? o.first : o.hair;
  if (coupeFile.empty())
    throw InputError("--rest needs the deformed coupe: hairgen shade --rest REST COUPE -o OUT");
  const Strands rest = readStrandsAs(o.rest, o.units);
  // One coupe, or every frame of a sequence (--frames): the rest's normals on each.
  const bool sequence = !o.frames.empty();
  const FrameRange frames = sequence ? parseFrameRange(o.frames, "--frames") : FrameRange{0, 0};
  if (sequence)
    for (const std::string* pattern : {&coupeFile, static_cast<const std::string*>(&o.output)})
      if (!isFramePattern(*pattern))
        throw InputError(*pattern + ": with --frames, write #### where the frame number goes");
  if (sequence) requireWritableOutput(framePath(o.output, frames.first));
  Progress progress("shade", "frames", size_t(frames.count()), sequence && !o.common.quiet);
  for (int f = frames.first; f <= frames.last; ++f) {
    const std::string in = sequence ? framePath(coupeFile, f).string() : coupeFile;
    const std::string written = sequence ? framePath(o.output, f).string() : o.output;
    const Strands deformed = readStrandsAs(in, o.units);
    stats.add("read", clock.lap());
    // What repose refuses is this frame's: its file goes in the message.
    const Strands out = namingFile(in, [&] { return repose(rest, deformed); });
    stats.add("repose", clock.lap());
    stats.counts()["strands"] = out.strandCount();
    stats.counts()["points"] = out.pointCount();
    warnDropped("shade", written, writeStrands(written, out));
    stats.add("write", clock.lap());
    if (!sequence) continue;
    keepCommittedOutputs();  // a finished frame stays, whatever a later one does
    progress.advance();
  }
  progress.finish();
  note(o.common, "shade: re-posed the normals of " + o.rest + " onto " +
                     (sequence ? std::to_string(frames.count()) + " frames" : coupeFile) + "; wrote " +
                     o.output);
}

// The volume's normals (and Anjyo's ambient) on a coupe, or on every frame of a sequence, each with its
// own volume; --vdb writes the volume too.
void shadeCoupes(const ShadeArgs& o, Stats& stats) {
  Stopwatch clock;
  if (o.first.empty() || o.hair.empty())
    throw InputError("shade needs a Setup and a coupe: hairgen shade SETUP --hair COUPE -o OUT");
  if (!o.vdb.empty() && !toLower(o.vdb).ends_with(".vdb"))
    throw InputError("--vdb " + o.vdb + ": the volume file must end in .vdb");
  // One coupe, or every frame of a sequence (--frames), each with its own volume.
  const bool sequence = !o.frames.empty();
  const FrameRange frames = sequence ? parseFrameRange(o.frames, "--frames") : FrameRange{0, 0};
  if (sequence) {
    for (const std::string* pattern : {&o.hair, &o.output})
      if (!isFramePattern(*pattern))
        throw InputError(*pattern + ": with --frames, write #### where the frame number goes");
    if (!o.vdb.empty() && !isFramePattern(o.vdb))
      throw InputError("--vdb " + o.vdb +
                       ": with --frames, each frame has its volume: write #### where the frame number goes");
    requireWritableOutput(framePath(o.output, frames.first));
  }
  Config config = loadStageConfig(o.first, o.common, SetupUse::kRender, stats);
  Progress progress("shade", "frames", size_t(frames.count()), sequence && !o.common.quiet);
  for (int f = frames.first; f <= frames.last; ++f) {
    auto frameOf = [&](const std::string& name) {
      return name.empty() || !sequence ? name : framePath(name, f).string();
    };
    const std::string hair = frameOf(o.hair), output = frameOf(o.output), vdb = frameOf(o.vdb);
    Strands coupe = readStrandsAs(hair, o.units);
    stats.add("read", clock.lap());
    ShadeResult shaded;
    try {
      shaded = shadeStage(o.common, config, std::move(coupe), stats, !vdb.empty());
    } catch (const InputError& e) {  // what is wrong with the coupe, said of its file
      if (!e.where().file.empty()) throw;
      throw InputError({hair, 0}, e.message());
    }
    clock.lap();
    // The volume first: if the coupe then cannot be written, runCommand removes the volume (no
    // partial output).
    if (!vdb.empty()) writeVdb(vdb, shaded.volume);
    warnDropped("shade", output, writeStrands(output, shaded.coupe));
    stats.add("write", clock.lap());
    if (!sequence) continue;
    keepCommittedOutputs();  // a finished frame stays, whatever a later one does
    progress.advance();
  }
  progress.finish();
  note(o.common, "shade: wrote " + (sequence ? std::to_string(frames.count()) + " frames " : std::string()) +
                     o.output + (o.vdb.empty() ? "" : " and " + o.vdb));
}

}  // namespace

void registerShade(CLI::App& app, int& exitCode) {
  auto options = std::make_shared<ShadeArgs>();
  CLI::App* cmd = app.add_subcommand(
      "shade",
      "Shading attributes into the cache: volumetric normals from the hair's density grid and shell (Render "
      "Info's "
      "VoxelSize, VolumePadding, ShellDensity), and a per-strand ambient from N(AmbientMean, "
      "AmbientDeviation) when "
      "Visuality Info asks. With --rest, re-poses a shaded rest coupe's normals onto a deformed one instead");
  cmd->add_option(
         "SETUP", options->first,
         "The Setup file (Render Info, Visuality Info, Hairstyle's Seed); with --rest, the deformed coupe")
      ->type_name("SETUP|COUPE");
  cmd->add_option("--hair", options->hair, "The coupe (" + readHairExtensionList() + ")")->type_name("FILE");
  addUnitFlags(*cmd, options->units, "the coupe");
  cmd->add_option("--rest", options->rest,
                  "A coupe shaded at rest; its normals are carried onto the coupe by "
                  "parallel-transport frames, with no volume built")
      ->type_name("REST");
  cmd->add_option("-o,--output", options->output, "Shaded coupe to write (.hair, .gltf, .glb, .ply, .usda)")
      ->type_name("FILE")
      ->required();
  cmd->add_option("--vdb", options->vdb,
                  "Also write the density and signed-distance grids as OpenVDB float grids "
                  "named 'density' and 'sdf'")
      ->type_name("FILE.vdb");
  cmd->add_option("--frames", options->frames,
                  "Every frame of a sequence: the coupe, -o and --vdb being patterns with ####")
      ->type_name("A-B");
  addCommonFlags(*cmd, options->common, true);
  cmd->callback([options, &exitCode] {
    exitCode = runCommand("shade", options->common, [&] {
      Stats stats("shade");
      hairFormatOf(options->output);
      if (!isFramePattern(options->output)) requireWritableOutput(options->output);
      if (!options->rest.empty())
        reposeCoupes(*options, stats);
      else
        shadeCoupes(*options, stats);
      stats.write(options->common);
    });
  });
}

}  // namespace hairgen::cli
