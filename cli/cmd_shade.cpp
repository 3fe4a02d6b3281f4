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

void registerShade(CLI::App& app, int& exitCode) {
  struct Options {
    CommonOptions common;
    std::string first, hair, rest, output, vdb, frames;
    UnitOptions units;
  };
  auto options = std::make_shared<Options>();
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
  cmd->add_option("--hair", options->hair, "The coupe (.hair, .gltf, .glb, .ply, .data)")->type_name("FILE");
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
      Stopwatch clock;
      if (!options->rest.empty()) {
        if (!options->vdb.empty()) throw InputError("--vdb needs a volume, which --rest does not build");
        if (!options->hair.empty() && !options->first.empty())
          throw InputError(
              "with --rest no Setup is read: give the deformed coupe once, as --hair or on its own");
        const std::string& coupeFile = options->hair.empty() ? options->first : options->hair;
        if (coupeFile.empty())
          throw InputError("--rest needs the deformed coupe: hairgen shade --rest REST COUPE -o OUT");
        const Strands rest = readStrandsAs(options->rest, options->units);
        // One coupe, or every frame of a sequence (--frames): the rest's normals on each.
        const bool sequence = !options->frames.empty();
        const FrameRange frames = sequence ? parseFrameRange(options->frames, "--frames") : FrameRange{0, 0};
        if (sequence)
          for (const std::string* pattern : {&coupeFile, static_cast<const std::string*>(&options->output)})
            if (!isFramePattern(*pattern))
              throw InputError(*pattern + ": with --frames, write #### where the frame number goes");
        if (sequence) requireWritableOutput(framePath(options->output, frames.first));
        Progress progress("shade", "frames", size_t(frames.count()), sequence && !options->common.quiet);
        for (int f = frames.first; f <= frames.last; ++f) {
          const std::string in = sequence ? framePath(coupeFile, f).string() : coupeFile;
          const std::string written = sequence ? framePath(options->output, f).string() : options->output;
          const Strands deformed = readStrandsAs(in, options->units);
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
        note(options->common, "shade: re-posed the normals of " + options->rest + " onto " +
                                  (sequence ? std::to_string(frames.count()) + " frames" : coupeFile) +
                                  "; wrote " + options->output);
        stats.write(options->common);
        return;
      }
      if (options->first.empty() || options->hair.empty())
        throw InputError("shade needs a Setup and a coupe: hairgen shade SETUP --hair COUPE -o OUT");
      if (!options->vdb.empty() && !toLower(options->vdb).ends_with(".vdb"))
        throw InputError("--vdb " + options->vdb + ": the volume file must end in .vdb");
      // One coupe, or every frame of a sequence (--frames), each with its own volume.
      const bool sequence = !options->frames.empty();
      const FrameRange frames = sequence ? parseFrameRange(options->frames, "--frames") : FrameRange{0, 0};
      if (sequence) {
        for (const std::string* pattern : {&options->hair, &options->output})
          if (!isFramePattern(*pattern))
            throw InputError(*pattern + ": with --frames, write #### where the frame number goes");
        if (!options->vdb.empty() && !isFramePattern(options->vdb))
          throw InputError(
              "--vdb " + options->vdb +
              ": with --frames, each frame has its volume: write #### where the frame number goes");
        requireWritableOutput(framePath(options->output, frames.first));
      }
      Config config = loadStageConfig(options->first, options->common, SetupUse::kRender, stats);
      Progress progress("shade", "frames", size_t(frames.count()), sequence && !options->common.quiet);
      for (int f = frames.first; f <= frames.last; ++f) {
        auto frameOf = [&](const std::string& name) {
          return name.empty() || !sequence ? name : framePath(name, f).string();
        };
        const std::string hair = frameOf(options->hair), output = frameOf(options->output),
                          vdb = frameOf(options->vdb);
        Strands coupe = readStrandsAs(hair, options->units);
        stats.add("read", clock.lap());
        ShadeResult shaded;
        try {
          shaded = shadeStage(options->common, config, std::move(coupe), stats, !vdb.empty());
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
      note(options->common, "shade: wrote " +
                                (sequence ? std::to_string(frames.count()) + " frames " : std::string()) +
                                options->output + (options->vdb.empty() ? "" : " and " + options->vdb));
      stats.write(options->common);
    });
  });
}

}  // namespace hairgen::cli
