// Preview movies of a frame sequence, made by Debian's ffmpeg (run as a separate program, its arguments
// passed as a list, never through a shell): an MP4 (H.264, yuv420p, plays everywhere) at the shot's
// frame rate, and a small looping GIF for READMEs and reviews. People look at motion, not at frame
// numbers.
#pragma once

#include <filesystem>
#include <string>

#include "libcore/util/frames.h"

namespace hairgen {

struct MovieOptions {
  double frameRate = 24.0;
  int gifWidth = 240;        // pixels; the GIF keeps the aspect
  double gifFrameRate = 12;  // frames per second of the GIF (every other frame at 24)
};

// Encodes the PNG files of `pngPattern` (#### for the frame number) for `frames` into `mp4` and `gif`
// (either may be empty: not wanted), each written through a temporary and renamed into place. Returns
// false, with nothing written, when ffmpeg is not installed; throws IoError when it fails.
bool writeMovie(const std::filesystem::path& pngPattern, const FrameRange& frames,
                const std::filesystem::path& mp4, const std::filesystem::path& gif,
                const MovieOptions& options = {});

}  // namespace hairgen
