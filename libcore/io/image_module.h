// The images hairgen reads through OpenImageIO (PNG, TIFF, JPEG, ... and any image's header for
// `hairgen info`) come from a module, libhairgen_images.so, that hairgen loads the first time it needs
// one. OpenImageIO brings about 260 shared libraries (FFmpeg, DICOM, camera RAW, ...) whose loading
// cost every command 0.2 s and 130 MB before it did anything; hairgen's own EXRs and PNG previews are
// written and read with OpenEXR and libpng directly, so only `diff` of non-EXR images and `info` of an
// image pay for it.
//
// The module is built beside the executable and found there (or in the build folder it was built in).
// Its functions never throw: they return false with a one-line message, which the caller turns into
// the error naming the file.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "libcore/model/image.h"

namespace hairgen {

// An image's header without its pixels, for `hairgen info`: size, channels and metadata.
struct ImageHeader {
  std::string format;  // OpenImageIO's name of the file format ("openexr")
  int width = 0, height = 0;
  std::vector<std::pair<std::string, std::string>> channels;    // name, type ("half", "float")
  std::vector<std::pair<std::string, std::string>> attributes;  // name, value as text, file order
};

struct ImageModule {
  const char* build;  // kImageModuleBuild: a module from another version or compiler is refused
  // Reads the image with the reader that `path`'s extension names, every channel as float; refuses one
  // that declares more than `maxSide` pixels a side, `maxChannels` channels or `budget` bytes.
  bool (*read)(const char* path, int maxSide, int maxChannels, uint64_t budget, Image* out,
               std::string* error);
  bool (*header)(const char* path, ImageHeader* out, std::string* error);
};
inline constexpr const char* kImageModuleBuild = HAIRGEN_VERSION " " __VERSION__;

}  // namespace hairgen

// The module's one symbol.
extern "C" const hairgen::ImageModule* hairgen_image_module();
