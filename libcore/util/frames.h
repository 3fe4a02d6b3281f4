// Frame sequences (DESIGN §8): file patterns with the frame number in them, and frame ranges.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>

namespace hairgen {

// An inclusive range of frames, `--frames A-B` (or a single frame `A`).
struct FrameRange {
  int first = 0, last = 0;
  int count() const { return last - first + 1; }
};

// Parses "A-B" or "A" (A <= B; negative frames are written "-5--1"). Throws InputError naming `flag`.
FrameRange parseFrameRange(std::string_view text, const std::string& flag);

// Whether `pattern` holds a frame-number placeholder: one run of '#' (its length the zero-padded
// width, any length) or one printf-style %0Nd / %d (N any width).
bool isFramePattern(const std::filesystem::path& pattern);

// The pattern with `frame` in place of its placeholder, zero-padded to its width (the width counts a
// negative frame's sign, which stays in front of the padding); wider numbers are written whole.
// Throws InputError when there is no placeholder, more than one, or when the frame's file name would
// be longer than the 255 bytes a file name can have.
std::filesystem::path framePath(const std::filesystem::path& pattern, int frame);

}  // namespace hairgen
