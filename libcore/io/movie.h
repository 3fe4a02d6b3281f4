// Preview movies of a frame sequence, made by Debian's ffmpeg (run as a separate program, its arguments
// passed as a list, never through a shell): an MP4 (H.264, yuv420p with BT.709's matrix, tagged
// BT.709, plays everywhere) at the shot's frame rate, and a looping GIF at the frames' size for
// READMEs and reviews. People look at motion, not at frame
// numbers.
#pragma once

#include <filesystem>
#include <string>

#include "libcore/util/frames.h"

namespace hairgen {

struct MovieOptions {
  double frameRate = 24.0;
  double gifFrameRate = 12;  // frames per second of the GIF (every other frame at 24)
};

// Encodes the PNG files of `pngPattern` (#### or %04d for the frame number) for `frames` into `mp4` and
// `gif` (either may be empty: not wanted), each written through a temporary and renamed into place.
// The frames are read here and piped to ffmpeg, and the outputs named to it with the file: protocol, so
// any path works (a folder with % or :, a name starting with -). An odd width or height is padded with
// one black column or row for H.264, which needs even sizes. Returns false, with nothing written, when
// ffmpeg is not installed; throws InputError for a frame that cannot be read, IoError when ffmpeg fails
// ("ffmpeg failed (exit N): its last message line"), with the failed file's temporary removed.
bool writeMovie(const std::filesystem::path& pngPattern, const FrameRange& frames,
                const std::filesystem::path& mp4, const std::filesystem::path& gif,
                const MovieOptions& options = {});

}  // namespace hairgen
