#include "libcore/io/exr_io.h"

#include <algorithm>
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
#include <OpenEXR/openexr.h>
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

// The OpenImageIO format whose extensions include `file`'s (case-insensitively), or "" when none does.
std::string imageFormatOf(const fs::path& file) {
  const std::string extension = toLower(file.extension().string());
  if (extension.size() < 2) return {};
  for (const auto& [format, extensions] : OIIO::get_extension_map())
    for (const std::string& e : extensions)
      if ("." + e == extension) return format;
  return {};
}

// Refuses a declared image hairgen does not read or that cannot fit in memory. The header is the
// attacker's: a 12 kB file can declare a 7 GB image, so this runs before anything is allocated.
// `chunkRows`: the reader decodes whole chunks of that many scanlines, so a shorter image costs a chunk.
void checkDeclaredSize(const FileLoc& where, int64_t width, int64_t height, int64_t channels,
                       int64_t chunkRows = 1) {
  const std::string pixels = std::to_string(width) + "x" + std::to_string(height) + " pixels";
  if (width <= 0 || height <= 0 || channels <= 0)
    throw InputError(where, "declares an image of " + pixels + " and " + std::to_string(channels) +
                                " channels; expected a 2D image");
  if (width > kMaxImageSide || height > kMaxImageSide || channels > kMaxImageChannels)
    throw InputError(where, "declares " + pixels + " and " + std::to_string(channels) +
                                " channels; hairgen reads at most " + std::to_string(kMaxImageSide) +
                                " pixels a side and " + std::to_string(kMaxImageChannels) + " channels");
  // Read interleaved, then split into planes: twice the float image at the peak.
  const int64_t rows = std::max(height, chunkRows);
  const uint64_t bytes = 2ull * uint64_t(width) * uint64_t(rows) * uint64_t(channels) * 4ull;
  if (bytes > memoryBudget())
    throw InputError(
        where, "declares " + pixels + " of " + std::to_string(channels) + " channels, " + formatBytes(bytes) +
                   " to read" +
                   (rows > height ? " in chunks of " + std::to_string(rows) + " scanlines" : "") +
                   ", more than the " + formatBytes(memoryBudget()) + " this machine has free");
}

// OpenEXR 3.1's C++ reader, which OpenImageIO uses, allocates what a header declares before it reads
// it: a 300-byte file made it zero 1.9 GB for one string attribute, and a 6-million-pixel-wide data
// window made it allocate 1.9 GB of line buffers when the file was opened (found by tests/fuzz/fuzz_exr).
// OpenEXRCore's parser checks every size against the file, so it reads an EXR's header first, and each
// part's declared size, chunks of scanlines included, is checked before OpenImageIO opens the file.
void checkExrHeader(const fs::path& file, const FileLoc& where) {
  std::string message;
  exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
  init.flags = EXR_CONTEXT_FLAG_STRICT_HEADER;  // else a bad attribute's size is reported, then skipped
  init.user_data = &message;
  init.error_handler_fn = [](exr_const_context_t context, exr_result_t, const char* text) {
    void* user = nullptr;  // the library prints nothing: the message goes into the error
    if (exr_get_user_data(context, &user) == EXR_ERR_SUCCESS && user) *static_cast<std::string*>(user) = text;
  };
  exr_context_t context = nullptr;
  const exr_result_t started = exr_start_read(&context, file.c_str(), &init);
  struct Finish {
    exr_context_t& context;
    ~Finish() { exr_finish(&context); }
  } finish{context};
  auto refuse = [&](exr_result_t result) {
    return InputError(where, "not a readable OpenEXR file: " +
                                 oneLine(message.empty() ? exr_get_default_error_message(result) : message));
  };
  if (started != EXR_ERR_SUCCESS) throw refuse(started);
  int parts = 0;
  if (const exr_result_t r = exr_get_count(context, &parts); r != EXR_ERR_SUCCESS) throw refuse(r);
  for (int part = 0; part < parts; ++part) {
    exr_attr_box2i_t window{};
    const exr_attr_chlist_t* channels = nullptr;
    if (const exr_result_t r = exr_get_data_window(context, part, &window); r != EXR_ERR_SUCCESS)
      throw refuse(r);
    if (const exr_result_t r = exr_get_channels(context, part, &channels); r != EXR_ERR_SUCCESS)
      throw refuse(r);
    exr_storage_t storage{};
    int32_t chunkRows = 1;  // up to 256 (DWAB); a tiled part decodes tiles
    if (exr_get_storage(context, part, &storage) == EXR_ERR_SUCCESS && storage == EXR_STORAGE_SCANLINE &&
        exr_get_scanlines_per_chunk(context, part, &chunkRows) != EXR_ERR_SUCCESS)
      chunkRows = 1;
    checkDeclaredSize(where, int64_t(window.max.x) - window.min.x + 1,
                      int64_t(window.max.y) - window.min.y + 1, channels ? channels->num_channels : 0,
                      chunkRows);
  }
}

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
  const FileLoc where{file.string(), 0};
  // Only the reader the extension names reads the file. OpenImageIO's open() would otherwise hand a
  // file its own reader refused to every reader it has (DICOM, FFmpeg, camera RAW, ...): a 1.6 kB
  // mangled .exr then cost gigabytes (found by tests/fuzz/fuzz_exr).
  const std::string format = imageFormatOf(file);
  if (format.empty())
    throw InputError(where, "no image format has the extension '" + file.extension().string() +
                                "'; name an image by its format (.exr, .png, .tif, ...)");
  if (format == "openexr") checkExrHeader(file, where);
  auto in = OIIO::ImageInput::create(format);
  if (!in) throw InputError(where, "cannot read image: " + OIIO::geterror());
  OIIO::ImageSpec spec;
  if (!in->open(file.string(), spec)) throw InputError(where, "cannot read image: " + in->geterror());
  if (spec.depth > 1)
    throw InputError(where,
                     "declares a volume " + std::to_string(spec.depth) + " pixels deep; expected a 2D image");
  checkDeclaredSize(where, spec.width, spec.height, spec.nchannels);
  Image image;
  image.width = spec.width;
  image.height = spec.height;
  const size_t pixels = size_t(spec.width) * spec.height;
  std::vector<float> interleaved(pixels * spec.nchannels);
  if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, interleaved.data()))
    throw InputError(where, "cannot read image: " + in->geterror());
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
