// OpenEXR output (DESIGN §6): one part; R G B A as half, every other channel as float; producer,
// config digest and camera in the header. Written beside the target and renamed into place.
#pragma once

#include <filesystem>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include <glm/glm.hpp>

#include "libcore/io/image_module.h"
#include "libcore/render/renderer.h"

namespace hairgen {

struct ExrMetadata {
  std::map<std::string, std::string> strings;  // e.g. "producer", "hairgen:configDigest"
  std::map<std::string, float> floats;         // e.g. "hairgen:fieldOfView"
  std::map<std::string, glm::ivec2> sizes;     // V2i attributes, e.g. "hairgen:resolution"
  std::map<std::string, int> ints;             // e.g. "hairgen:frame", a sequence's frame number
  double framesPerSecond = 0.0;                // > 0: OpenEXR's framesPerSecond, as a rational
  // OpenEXR's camera attributes (ImfStandardAttributes.h), given as glm matrices for column vectors
  // (p' = M p) and written transposed for Imath's row vectors (p' = p M): worldToCamera into camera
  // space with +z forward, worldToNDC to (0, 0) at the image's top-left corner and (1, 1) at its
  // bottom-right after the divide by w (views.h: openExrWorldToCamera, openExrWorldToNdc).
  glm::dmat4 worldToCamera{1.0}, worldToNdc{1.0};
  bool camera = false;  // write worldToCamera / worldToNDC
};

// The threads that compress a written EXR's chunks (OpenEXR's global pool, process-wide; 0 for none):
// a command sets it once, to its --threads. The file's bytes are the same for any count.
void setExrThreads(int threads);

void writeExr(const std::filesystem::path& file, const Image& image, const ExrMetadata& metadata);

// An image, every channel as float: an EXR with OpenEXR, any other format OpenImageIO reads through
// hairgen's image module (image_module.h). Throws InputError naming the file.
Image readImage(const std::filesystem::path& file);

// An image's header, for `hairgen info` (through the image module, for every format).
ImageHeader readImageHeader(const std::filesystem::path& file);

// An 8-bit sRGB PNG for people to look at: premultiplied R G B A over `background` (R G B + (1 − A) ×
// background), clamped to [0, 1]. An image without A is shown as it is.
void writePreview(const std::filesystem::path& file, const Image& image, const glm::dvec3& background);

}  // namespace hairgen
