#include "libcore/io/exr_io.h"

#include <cmath>

#include <ImathMatrix.h>
#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFloatAttribute.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfMatrixAttribute.h>
#include <OpenEXR/ImfOutputFile.h>
#include <OpenEXR/ImfStandardAttributes.h>
#include <OpenEXR/ImfStringAttribute.h>
#include <OpenEXR/ImfVecAttribute.h>
#include <OpenImageIO/imageio.h>
#include <half.h>

#include "libcore/util/error.h"
#include "libcore/util/file_util.h"
#include "libcore/util/resources.h"
#include "libcore/util/text.h"

namespace hairgen {
namespace {

namespace fs = std::filesystem;

Imath::M44f toImath(const glm::dmat4& m) {
  // glm is column-major with column vectors; Imath uses row vectors (p' = p M), so M = transpose.
  Imath::M44f r;
  for (int row = 0; row < 4; ++row)
    for (int col = 0; col < 4; ++col) r[row][col] = static_cast<float>(m[row][col]);
  return r;
}

// Far beyond any frame hairgen renders (Resolution is at most 16384), and small enough that a header
// cannot make the reader allocate without bound.
constexpr int kMaxImageSide = 65536;
constexpr int kMaxImageChannels = 1024;

bool isHalf(const std::string& c) {
  return c == "R" || c == "G" || c == "B" || c == "A";
}

}  // namespace

void writeExr(const fs::path& file, const Image& image, const ExrMetadata& metadata) {
  Imf::Header header(image.width, image.height);
  header.compression() = Imf::ZIP_COMPRESSION;
  for (const auto& [key, value] : metadata.strings) header.insert(key, Imf::StringAttribute(value));
  for (const auto& [key, value] : metadata.floats) header.insert(key, Imf::FloatAttribute(value));
  for (const auto& [key, value] : metadata.sizes)
    header.insert(key, Imf::V2iAttribute(Imath::V2i(value.x, value.y)));
  if (metadata.camera) {
    Imf::addWorldToCamera(header, toImath(metadata.worldToCamera));
    Imf::addWorldToNDC(header, toImath(metadata.worldToNdc));
  }
  std::vector<std::vector<half>> halves(image.channels.size());
  Imf::FrameBuffer frame;
  for (size_t c = 0; c < image.channels.size(); ++c) {
    const std::string& name = image.channels[c];
    if (isHalf(name)) {
      header.channels().insert(name, Imf::Channel(Imf::HALF));
      halves[c].assign(image.planes[c].begin(), image.planes[c].end());
      frame.insert(name, Imf::Slice(Imf::HALF, reinterpret_cast<char*>(halves[c].data()), sizeof(half),
                                    sizeof(half) * image.width));
    } else {
      header.channels().insert(name, Imf::Channel(Imf::FLOAT));
      frame.insert(name,
                   Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(const_cast<float*>(image.planes[c].data())),
                              sizeof(float), sizeof(float) * image.width));
    }
  }
  writeThroughTemporary(file, [&](const fs::path& temporary) {
    try {
      Imf::OutputFile out(temporary.c_str(), header);
      out.setFrameBuffer(frame);
      out.writePixels(image.height);
    } catch (const std::exception& e) {
      throw IoError("cannot write " + file.string() + ": " + e.what());
    }
  });
}

Image readImage(const fs::path& file) {
  requireRegularFile(file);
  auto in = OIIO::ImageInput::open(file.string());
  if (!in) throw InputError({file.string(), 0}, "cannot read image: " + OIIO::geterror());
  const OIIO::ImageSpec& spec = in->spec();
  // The header is the attacker's: a 12 kB file can declare a 7 GB image. Size it before allocating.
  const FileLoc where{file.string(), 0};
  if (spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0 || spec.depth > 1)
    throw InputError(where, "declares an image of " + std::to_string(spec.width) + "x" +
                                std::to_string(spec.height) + " pixels and " +
                                std::to_string(spec.nchannels) + " channels; expected a 2D image");
  if (spec.width > kMaxImageSide || spec.height > kMaxImageSide || spec.nchannels > kMaxImageChannels)
    throw InputError(where, "declares " + std::to_string(spec.width) + "x" + std::to_string(spec.height) +
                                " pixels and " + std::to_string(spec.nchannels) +
                                " channels; hairgen reads at most " + std::to_string(kMaxImageSide) +
                                " pixels a side and " + std::to_string(kMaxImageChannels) + " channels");
  // Read interleaved, then split into planes: twice the float image at the peak.
  const uint64_t bytes =
      2ull * uint64_t(spec.width) * uint64_t(spec.height) * uint64_t(spec.nchannels) * 4ull;
  if (bytes > memoryBudget())
    throw InputError(where, "declares " + std::to_string(spec.width) + "x" + std::to_string(spec.height) +
                                " pixels of " + std::to_string(spec.nchannels) + " channels, " +
                                formatBytes(bytes) + " to read, more than the " +
                                formatBytes(memoryBudget()) + " this machine has free");
  Image image;
  image.width = spec.width;
  image.height = spec.height;
  const size_t pixels = size_t(spec.width) * spec.height;
  std::vector<float> interleaved(pixels * spec.nchannels);
  if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, interleaved.data()))
    throw InputError({file.string(), 0}, "cannot read image: " + in->geterror());
  for (int c = 0; c < spec.nchannels; ++c) {
    image.channels.push_back(spec.channelnames[c]);
    std::vector<float> plane(pixels);
    for (size_t i = 0; i < pixels; ++i) plane[i] = interleaved[i * spec.nchannels + c];
    image.planes.push_back(std::move(plane));
  }
  return image;
}

ImageHeader readImageHeader(const fs::path& file) {
  requireRegularFile(file);
  auto in = OIIO::ImageInput::open(file.string());
  if (!in) throw InputError({file.string(), 0}, "cannot read image: " + oneLine(OIIO::geterror()));
  const OIIO::ImageSpec& spec = in->spec();
  ImageHeader header;
  header.format = in->format_name();
  header.width = spec.width;
  header.height = spec.height;
  for (int c = 0; c < spec.nchannels; ++c)
    header.channels.emplace_back(spec.channelnames[c], spec.channelformat(c).c_str());
  for (const OIIO::ParamValue& p : spec.extra_attribs)
    header.attributes.emplace_back(p.name().string(), oneLine(p.get_string(16)));
  return header;
}

void writePreview(const fs::path& file, const Image& image, const glm::dvec3& background) {
  const size_t pixels = size_t(image.width) * image.height;
  std::vector<unsigned char> rgb(pixels * 3);
  const char* names[3] = {"R", "G", "B"};
  const std::vector<float>* alpha = image.has("A") ? &image.plane("A") : nullptr;
  for (int c = 0; c < 3; ++c) {
    const std::vector<float>& plane = image.plane(names[c]);
    for (size_t i = 0; i < pixels; ++i) {
      const double over = alpha ? double(plane[i]) + (1.0 - double((*alpha)[i])) * background[c] : plane[i];
      const double v = std::clamp(over, 0.0, 1.0);
      const double srgb = v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055;
      rgb[i * 3 + c] = static_cast<unsigned char>(std::lround(srgb * 255.0));
    }
  }
  auto out = OIIO::ImageOutput::create(file.string());
  if (!out) throw IoError("cannot write " + file.string() + ": " + OIIO::geterror());
  OIIO::ImageSpec spec(image.width, image.height, 3, OIIO::TypeDesc::UINT8);
  spec.attribute("Software", "hairgen " HAIRGEN_VERSION);
  writeThroughTemporary(file, [&](const fs::path& temporary) {
    if (!out->open(temporary.string(), spec) || !out->write_image(OIIO::TypeDesc::UINT8, rgb.data()) ||
        !out->close())
      throw IoError("cannot write " + file.string() + ": " + out->geterror());
  });
}

}  // namespace hairgen
