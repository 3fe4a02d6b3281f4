#include "libcore/util/frames.h"

#include <algorithm>
#include <cstdint>

#include "libcore/util/error.h"
#include "libcore/util/text.h"

namespace hairgen {
namespace {

// The longest file name Linux file systems hold (NAME_MAX), in bytes.
constexpr size_t kMaxNameBytes = 255;

// Where the placeholder is in the file name: [begin, end) and its width; begin == npos when absent.
struct Placeholder {
  size_t begin = std::string::npos, end = 0;
  size_t width = 0;  // digits, at least
  int count = 0;     // placeholders found
};

Placeholder findPlaceholder(const std::string& name) {
  Placeholder p;
  for (size_t i = 0; i < name.size();) {
    if (name[i] == '#') {
      size_t j = i;
      while (j < name.size() && name[j] == '#') ++j;
      if (p.count++ == 0) {
        p.begin = i;
        p.end = j;
        p.width = j - i;
      }
      i = j;
    } else if (name[i] == '%') {
      size_t j = i + 1;
      size_t width = 0;  // saturated: a width past any file name's length is refused by framePath
      while (j < name.size() && name[j] >= '0' && name[j] <= '9')
        width = std::min<size_t>(width * 10 + size_t(name[j++] - '0'), kMaxNameBytes + 1);
      if (j < name.size() && name[j] == 'd') {
        if (p.count++ == 0) {
          p.begin = i;
          p.end = j + 1;
          p.width = width;
        }
        i = j + 1;
      } else {
        ++i;
      }
    } else {
      ++i;
    }
  }
  return p;
}

}  // namespace

FrameRange parseFrameRange(std::string_view text, const std::string& flag) {
  auto bad = [&] {
    return InputError(flag + " " + std::string(text) + ": expected FIRST-LAST (e.g. 1-48) or one frame");
  };
  // The separator is the first '-' after the first character (so "-5--1" splits at the second '-').
  size_t dash = text.find('-', 1);
  std::optional<int64_t> a = parseInt(text.substr(0, dash == std::string_view::npos ? text.size() : dash));
  std::optional<int64_t> b = dash == std::string_view::npos ? a : parseInt(text.substr(dash + 1));
  if (!a || !b || *a < -1000000000 || *b > 1000000000) throw bad();
  if (*b < *a) throw InputError(flag + " " + std::string(text) + ": the last frame is before the first");
  return {int(*a), int(*b)};
}

bool isFramePattern(const std::filesystem::path& pattern) {
  return findPlaceholder(pattern.filename().string()).count > 0;
}

std::filesystem::path framePath(const std::filesystem::path& pattern, int frame) {
  const std::string name = pattern.filename().string();
  const Placeholder p = findPlaceholder(name);
  if (p.count == 0)
    throw InputError({pattern.string(), 0},
                     "has no frame number in its name; write #### (or %04d) where it goes");
  if (p.count > 1) throw InputError({pattern.string(), 0}, "has more than one frame-number placeholder");
  // The digits zero-padded to the placeholder's width, however wide: every frame its own name.
  const std::string magnitude = std::to_string(frame < 0 ? -int64_t(frame) : int64_t(frame));
  std::string digits = frame < 0 ? "-" : "";
  if (p.width > magnitude.size() + digits.size())
    digits.append(p.width - magnitude.size() - digits.size(), '0');
  digits += magnitude;
  const std::string file = name.substr(0, p.begin) + digits + name.substr(p.end);
  if (file.size() > kMaxNameBytes)
    throw InputError({pattern.string(), 0}, "makes frame file names of " + std::to_string(file.size()) +
                                                " bytes, longer than the " + std::to_string(kMaxNameBytes) +
                                                " a file name can have; write a shorter name or fewer #");
  std::filesystem::path out = pattern;
  out.replace_filename(file);
  return out;
}

}  // namespace hairgen
