// hairgen convert IN OUT: between .hair, .gltf, .glb, .ply and .data, and to .usda, keeping every
// attribute both formats carry; --units and --up-axis bring a file made elsewhere to metres, +y up.
// With --frames A-B: every frame of a sequence (#### in IN and OUT), or the frames as one animated USD
// stage (OUT a .usda without ####), the guides (--guides) beside the strands.
#include <iostream>

#include "cli/commands.h"
#include "cli/common.h"
#include "libcore/io/hair_cache.h"
#include "libcore/io/usd_io.h"
#include "libcore/util/file_util.h"
#include "libcore/util/frames.h"
#include "libcore/util/progress.h"

namespace hairgen::cli {
namespace {

struct ConvertOptions {
  CommonOptions common;
  UnitOptions units;
  std::string input, output, outputFlag, frames, guides;
  double fps = 0.0;
  bool ascii = false;
};

// Read as convert reads: a file made elsewhere gets this conversion as its hairgen provenance.
Strands readForConvert(const std::string& file, const UnitOptions& units) {
  Strands strands = readStrandsAs(file, units);
  if (strands.provenance.producer.empty()) {
    strands.provenance.producer = "hairgen " HAIRGEN_VERSION;
    strands.provenance.stage = "convert";
  }
  return strands;
}

void requirePattern(const std::string& name, const char* what) {
  if (!isFramePattern(name))
    throw InputError(name + ": with --frames, " + what + " needs #### where the frame number goes");
}

// Every input frame is there before anything is written, so a missing one costs no output.
void requireFrames(const std::string& pattern, const FrameRange& frames) {
  for (int f = frames.first; f <= frames.last; ++f) {
    const std::filesystem::path file = framePath(pattern, f);
    std::error_code ec;
    if (!std::filesystem::is_regular_file(file, ec))
      throw InputError({file.string(), 0}, "cannot open: frame " + std::to_string(f) + " of --frames " +
                                               std::to_string(frames.first) + "-" +
                                               std::to_string(frames.last) + " is missing");
  }
}

// The frames as one stage: the strands (IN, animated when it is a pattern, else at rest) and the guides.
UsdWritten convertToShot(const ConvertOptions& o, const FrameRange& frames, Stats& stats) {
  const bool inputAnimated = isFramePattern(o.input);
  if (inputAnimated) requireFrames(o.input, frames);
  if (!o.guides.empty()) {
    requirePattern(o.guides, "--guides");
    requireFrames(o.guides, frames);
  } else if (!inputAnimated) {
    requirePattern(o.input, "IN");
  }
  auto prim = [&](const std::string& pattern, bool animated) {
    return UsdShotPrim{[&o, pattern, animated](int f) {
                         return readForConvert(animated ? framePath(pattern, f).string() : pattern, o.units);
                       },
                       pattern, animated};
  };
  UsdShot shot;
  shot.frames = frames;
  if (o.fps > 0.0) shot.framesPerSecond = o.fps;
  // IN alone is the guides when it is what grow or simulate wrote, else the strands.
  const bool inputIsGuides =
      o.guides.empty() && areGuides(readForConvert(framePath(o.input, frames.first).string(), o.units));
  (inputIsGuides ? shot.guides : shot.strands) = prim(o.input, inputAnimated);
  if (!o.guides.empty()) shot.guides = prim(o.guides, true);
  const UsdWritten written = writeUsdShot(o.output, shot);
  stats.counts()["frames"] = frames.count();
  return written;
}

// --frames with #### in IN and OUT: each frame converted on its own; what was written, for the note.
std::string convertFrames(const ConvertOptions& o, const FrameRange& frames, Stats& stats,
                          WriteReport& report) {
  Stopwatch clock;
  requirePattern(o.input, "IN");
  requirePattern(o.output, "OUT");
  requireFrames(o.input, frames);
  requireWritableOutput(framePath(o.output, frames.first));
  Progress progress("convert", "frames", size_t(frames.count()), !o.common.quiet);
  // No keepCommittedOutputs: a frame that fails removes the frames written before it.
  for (int f = frames.first; f <= frames.last; ++f) {
    const Strands strands = readForConvert(framePath(o.input, f).string(), o.units);
    stats.add("read", clock.lap());
    report.droppedStrands +=
        writeStrands(framePath(o.output, f), strands, WriteOptions{o.ascii}).droppedStrands;
    stats.add("write", clock.lap());
    progress.advance();
  }
  progress.finish();
  stats.counts()["frames"] = frames.count();
  return std::to_string(frames.count()) + " frames";
}

// The output named once, its format known and the flags fitting it, before anything is read. Returns the
// output's format.
HairFormat checkOptions(ConvertOptions& o) {
  if (!o.outputFlag.empty() && !o.output.empty()) throw InputError("give the output once, as OUT or as -o");
  if (o.output.empty()) o.output = o.outputFlag;
  if (o.output.empty()) throw InputError("convert needs an output: hairgen convert IN OUT (or -o OUT)");
  const HairFormat format = hairFormatOf(o.output);  // a bad extension before reading anything
  if (o.ascii && format != HairFormat::kPly)
    throw InputError("--ascii is for a .ply output; " + o.output + " is " + describe(format));
  const bool sequence = !o.frames.empty();
  const bool stage = sequence && format == HairFormat::kUsda && !isFramePattern(o.output);
  if (!o.guides.empty() && !stage)
    throw InputError("--guides is for one animated stage: --frames A-B and an OUT .usda without ####");
  if (o.fps > 0.0 && !stage) throw InputError("--fps is for one animated stage: --frames A-B and a .usda");
  return format;
}

}  // namespace

void registerConvert(CLI::App& app, int& exitCode) {
  auto options = std::make_shared<ConvertOptions>();
  CLI::App* cmd = app.add_subcommand(
      "convert",
      "Convert strands between .hair, .gltf, .glb, .ply and .data, or export them to .usda (format from the "
      "extension); with --frames, a sequence frame by frame, or into one animated .usda");
  cmd->add_option("IN", options->input,
                  "Input " + readHairExtensionList() + " (#### for a frame with --frames)")
      ->required();
  cmd->add_option("OUT", options->output, "Output " + hairExtensionList() + " (written atomically); or -o");
  cmd->add_option("-o,--output", options->outputFlag, "The output, instead of OUT")->type_name("FILE");
  addUnitFlags(*cmd, options->units, "IN");
  cmd->add_flag("--ascii", options->ascii, "Write a .ply as ASCII text instead of binary little-endian");
  cmd->add_option("--frames", options->frames,
                  "Convert frames A to B: IN and OUT hold ####; or OUT is one .usda stage with the frames as "
                  "time samples (IN then a pattern, or a rest coupe beside --guides)")
      ->type_name("A-B");
  cmd->add_option("--guides", options->guides,
                  "With --frames and a .usda: the guides' frames (a pattern), written beside IN as "
                  "/hair/guides")
      ->type_name("PATTERN");
  cmd->add_option("--fps", options->fps,
                  "Frames per second of the .usda stage (default: the caches' own frame rate)")
      ->type_name("R")
      ->check(CLI::Range(1e-3, 1e4));
  addCommonFlags(*cmd, options->common, false);
  cmd->callback([options, &exitCode] {
    exitCode = runCommand("convert", options->common, [&] {
      Stats stats("convert");
      ConvertOptions& o = *options;
      const HairFormat format = checkOptions(o);
      const bool sequence = !o.frames.empty();
      const bool stage = sequence && format == HairFormat::kUsda && !isFramePattern(o.output);
      const FrameRange frames = sequence ? parseFrameRange(o.frames, "--frames") : FrameRange{0, 0};
      Stopwatch clock;
      WriteReport report;
      std::string what;
      if (stage) {
        requireWritableOutput(o.output);
        report.droppedStrands = convertToShot(o, frames, stats).droppedStrands;
        stats.time("convert", clock.lap());
        what = "frames " + std::to_string(frames.first) + "-" + std::to_string(frames.last) + " as one stage";
      } else if (sequence) {
        what = convertFrames(o, frames, stats, report);
      } else {
        requireWritableOutput(o.output);  // before the read: a bad output is bad usage (exit 2)
        const Strands strands = readForConvert(o.input, o.units);
        stats.time("read", clock.lap());
        report = writeStrands(o.output, strands, WriteOptions{o.ascii});
        stats.time("write", clock.lap());
        stats.counts()["strands"] = strands.strandCount();
        stats.counts()["points"] = strands.pointCount();
        what = std::to_string(strands.strandCount()) + " strands, " + std::to_string(strands.pointCount()) +
               " points" +
               (strands.provenance.metres && strands.provenance.yUp
                    ? ""
                    : "; units or up axis unknown: give --units and --up-axis");
      }
      stats.counts()["droppedStrands"] = report.droppedStrands;
      warnDropped("convert", o.output, report);
      note(o.common, "wrote " + o.output + " (" + what + ")");
      stats.write(o.common);
    });
  });
}

}  // namespace hairgen::cli
