// hairgen movie PATTERN --frames A-B -o beauty.mp4 [--gif beauty.gif] [--fps R]: a shot's preview movie
// from its PNG frames, as `hairgen run` makes it; the last task of a farm plan for a shot.
#include <filesystem>
#include <string>
#include <system_error>
#include <vector>

#include "cli/commands.h"
#include "cli/common.h"
#include "libcore/io/movie.h"
#include "libcore/util/file_util.h"
#include "libcore/util/frames.h"

namespace hairgen::cli {

void registerMovie(CLI::App& app, int& exitCode) {
  struct Options {
    CommonOptions common;
    std::string pattern, frames, output, gif;
    double fps = 24.0;
  };
  auto options = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand(
      "movie",
      "Encode a shot's PNG frames into the preview movie `run` writes (H.264 MP4 with Debian's ffmpeg, an "
      "odd width or height padded to even, and a small GIF): the farm's last task for a shot; when ffmpeg "
      "fails, exit 1 with its last message and no movie");
  cmd->add_option("PATTERN", options->pattern,
                  "The frames, #### standing for the frame number (beauty.####.png)")
      ->required();
  cmd->add_option("--frames", options->frames, "The frames to encode")->type_name("A-B")->required();
  cmd->add_option("-o,--output", options->output, "The MP4 to write (written atomically)")
      ->type_name("FILE.mp4")
      ->required();
  cmd->add_option("--gif", options->gif, "Also a GIF for a README or a review page")->type_name("FILE.gif");
  cmd->add_option("--fps", options->fps, "Frames per second, 0.001 to 10000 (the Dynamics FrameRate)")
      ->type_name("FPS")
      ->check(CLI::Range(0.001, 10000.0));
  addCommonFlags(*cmd, options->common, false);
  cmd->callback([options, &exitCode] {
    exitCode = runCommand("movie", options->common, [&] {
      Stats stats("movie");
      if (!isFramePattern(options->pattern))
        throw InputError(options->pattern + ": write #### where the frame number goes");
      const FrameRange frames = parseFrameRange(options->frames, "--frames");
      // The movie (and GIF) checked before ffmpeg runs, and never one of the frames it encodes.
      std::vector<std::string> outputs = {options->output};
      if (!options->gif.empty()) outputs.push_back(options->gif);
      for (const std::string& o : outputs) requireWritableOutput(o);
      for (int f = frames.first; f <= frames.last; ++f) {
        const std::string frame = framePath(options->pattern, f);
        requireRegularFile(frame);
        std::error_code ec;
        for (const std::string& o : outputs)
          if (std::filesystem::equivalent(o, frame, ec))
            throw InputError({o, 0}, "is frame " + std::to_string(f) + " of the movie; name another file");
      }
      if (outputs.size() == 2 && std::filesystem::path(outputs[0]).lexically_normal() ==
                                     std::filesystem::path(outputs[1]).lexically_normal())
        throw InputError({options->gif, 0}, "is also the movie (-o); name another file for the GIF");
      Stopwatch clock;
      MovieOptions movie;
      movie.frameRate = options->fps;
      if (!writeMovie(options->pattern, frames, options->output, options->gif, movie))
        throw IoError("ffmpeg is not installed (scripts/setup.sh installs it), so no movie was made");
      stats.time("movie", clock.lap());
      stats.counts()["frames"] = frames.count();
      note(options->common,
           "movie: wrote " + options->output + (options->gif.empty() ? "" : " and " + options->gif));
      stats.write(options->common);
    });
  });
}

}  // namespace hairgen::cli
