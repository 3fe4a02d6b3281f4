// libhairgen_images.so: OpenImageIO's readers behind the interface of image_module.h. Built as a module
// of its own, so that only the commands that read such an image load OpenImageIO.
#include "libcore/io/image_module.h"

#include <algorithm>
#include <cctype>
#include <exception>
#include <filesystem>
#include <memory>

#include <OpenImageIO/imageio.h>

namespace hairgen {
namespace {

std::string oneLine(std::string text) {
  std::replace(text.begin(), text.end(), '\n', ' ');
  std::replace(text.begin(), text.end(), '\r', ' ');
  while (!text.empty() && text.back() == ' ') text.pop_back();
  return text;
}

// The OpenImageIO format whose extensions include `file`'s (case-insensitively), or "" when none does.
std::string formatOf(const std::filesystem::path& file) {
  std::string extension = file.extension().string();
  for (char& c : extension) c = char(std::tolower(static_cast<unsigned char>(c)));
  if (extension.size() < 2) return {};
  for (const auto& [format, extensions] : OIIO::get_extension_map())
    for (const std::string& e : extensions)
      if ("." + e == extension) return format;
  return {};
}

bool read(const char* path, int maxSide, int maxChannels, uint64_t budget, Image* out,
          std::string* error) try {
  const std::filesystem::path file(path);
  // Only the reader the extension names reads the file. OpenImageIO's open() would otherwise hand a
  // file its own reader refused to every reader it has (DICOM, FFmpeg, camera RAW, ...): a 1.6 kB
  // mangled .exr then cost gigabytes (found by tests/fuzz/fuzz_exr).
  const std::string format = formatOf(file);
  if (format.empty()) {
    *error = "no image format has the extension '" + file.extension().string() +
             "'; name an image by its format (.exr, .png, .tif, ...)";
    return false;
  }
  auto in = OIIO::ImageInput::create(format);
  if (!in) {
    *error = "cannot read image: " + oneLine(OIIO::geterror());
    return false;
  }
  OIIO::ImageSpec spec;
  if (!in->open(path, spec)) {
    *error = "cannot read image: " + oneLine(in->geterror());
    return false;
  }
  const std::string pixels = std::to_string(spec.width) + "x" + std::to_string(spec.height) + " pixels";
  if (spec.depth > 1 || spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0) {
    *error = "declares an image of " + pixels + ", " + std::to_string(spec.depth) + " deep, and " +
             std::to_string(spec.nchannels) + " channels; expected a 2D image";
    return false;
  }
  // Read interleaved, then split into planes: twice the float image at the peak.
  const uint64_t bytes =
      2ull * uint64_t(spec.width) * uint64_t(spec.height) * uint64_t(spec.nchannels) * 4ull;
  if (spec.width > maxSide || spec.height > maxSide || spec.nchannels > maxChannels || bytes > budget) {
    *error = "declares " + pixels + " and " + std::to_string(spec.nchannels) +
             " channels, more than hairgen reads (" + std::to_string(maxSide) + " pixels a side, " +
             std::to_string(maxChannels) + " channels, the memory this machine has free)";
    return false;
  }
  out->width = spec.width;
  out->height = spec.height;
  const size_t count = size_t(spec.width) * size_t(spec.height);
  std::vector<float> interleaved(count * size_t(spec.nchannels));
  if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, interleaved.data())) {
    *error = "cannot read image: " + oneLine(in->geterror());
    return false;
  }
  for (int c = 0; c < spec.nchannels; ++c) {
    out->channels.push_back(spec.channelnames[size_t(c)]);
    std::vector<float> plane(count);
    for (size_t i = 0; i < count; ++i) plane[i] = interleaved[i * size_t(spec.nchannels) + size_t(c)];
    out->planes.push_back(std::move(plane));
  }
  return true;
} catch (const std::exception& e) {
  *error = "cannot read image: " + oneLine(e.what());
  return false;
}

bool header(const char* path, ImageHeader* out, std::string* error) try {
  auto in = OIIO::ImageInput::open(path);
  if (!in) {
    *error = "cannot read image: " + oneLine(OIIO::geterror());
    return false;
  }
  const OIIO::ImageSpec& spec = in->spec();
  out->format = in->format_name();
  out->width = spec.width;
  out->height = spec.height;
  for (int c = 0; c < spec.nchannels; ++c)
    out->channels.emplace_back(spec.channelnames[size_t(c)], spec.channelformat(c).c_str());
  for (const OIIO::ParamValue& p : spec.extra_attribs)
    out->attributes.emplace_back(p.name().string(), oneLine(p.get_string(16)));
  return true;
} catch (const std::exception& e) {
  *error = "cannot read image: " + oneLine(e.what());
  return false;
}

const ImageModule kModule{kImageModuleBuild, read, header};

}  // namespace
}  // namespace hairgen

extern "C" __attribute__((visibility("default"))) const hairgen::ImageModule* hairgen_image_module() {
  return &hairgen::kModule;
}
