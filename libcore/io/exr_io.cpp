#include "libcore/io/exr_io.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <mutex>
#include <string_view>

#include <ImathMatrix.h>
#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFloatAttribute.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfIntAttribute.h>
#include <OpenEXR/ImfMatrixAttribute.h>
#include <OpenEXR/ImfOutputFile.h>
#include <OpenEXR/ImfRationalAttribute.h>
#include <OpenEXR/ImfStandardAttributes.h>
#include <OpenEXR/ImfStringAttribute.h>
#include <OpenEXR/ImfThreading.h>
#include <OpenEXR/ImfVecAttribute.h>
#include <OpenEXR/openexr.h>
#include <dlfcn.h>
#include <half.h>
#include <png.h>

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

// A frame rate as OpenEXR's rational: NTSC's rates (23.976, 29.97, 59.94 as written in a Setup) as
// the exact n·1000/1001 they stand for, any other as Imath's nearest rational.
Imf::Rational framesPerSecond(double rate) {
  const double ntsc = std::round(rate * 1.001);
  if (std::abs(rate - ntsc * 1000.0 / 1001.0) < 5e-4 && std::abs(rate - std::round(rate)) > 1e-3)
    return Imf::Rational(int(ntsc) * 1000, 1001);
  return Imf::Rational(rate);
}

// Far beyond any frame hairgen renders (Resolution is at most 16384), and small enough that a header
// cannot make the reader allocate without bound.
constexpr int kMaxImageSide = 65536;
constexpr int kMaxImageChannels = 1024;

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

// The most raw pixel bytes one byte of a chunk can decode to under each compression, generously: a
// header whose image would need more than this of its file is a lie told to make the reader allocate
// (a 12 kB file declaring 16384x16384 pixels). NONE stores the pixels; RLE's longest run is 128 bytes
// in two; deflate (ZIP, ZIPS, and PXR24 after its 32-to-24-bit step) expands at most 1032 times; PIZ's
// Huffman codes runs of 255 values in a few bits; B44 stores a 4x4 block of halves in 14 bytes (B44A a
// flat one in 3); DWA keeps one DC value per 8x8 block and deflates those. Unknown: no bound.
double maxExpansion(exr_compression_t compression) {
  switch (compression) {
    case EXR_COMPRESSION_NONE:
      return 1.0;
    case EXR_COMPRESSION_RLE:
      return 64.0;
    case EXR_COMPRESSION_ZIPS:
    case EXR_COMPRESSION_ZIP:
    case EXR_COMPRESSION_PIZ:
      return 1100.0;
    case EXR_COMPRESSION_PXR24:
      return 1400.0;
    case EXR_COMPRESSION_B44:
    case EXR_COMPRESSION_B44A:
      return 12.0;
    case EXR_COMPRESSION_DWAA:
    case EXR_COMPRESSION_DWAB:
      return 64.0 * 1100.0;
    default:
      return 1e300;
  }
}

// Sizes a part's declared pixels against the file that holds them, before anything is allocated: its
// chunks' offset table must fit in the file, its raw pixels must be what the file's bytes can decode
// to, and (for scanlines) every chunk's leader must be in the file, its packed bytes too.
void checkAgainstFile(exr_const_context_t context, int part, const FileLoc& where, uint64_t fileBytes,
                      uint64_t rawBytes, exr_storage_t storage, const exr_attr_box2i_t& window,
                      int32_t chunkRows, const std::function<InputError(exr_result_t)>& refuse) {
  int32_t chunks = 0;
  if (const exr_result_t r = exr_get_chunk_count(context, part, &chunks); r != EXR_ERR_SUCCESS)
    throw refuse(r);
  // Per chunk: its 8-byte entry in the offset table and a leader of at least 8 bytes.
  if (chunks < 0 || uint64_t(chunks) * 16u > fileBytes)
    throw InputError(where, "declares " + std::to_string(chunks) + " chunks of pixels, more than the " +
                                std::to_string(fileBytes) + "-byte file can hold");
  // A deep part's pixels are sample counts and lists, whose sizes its chunks give, not its header.
  if (storage == EXR_STORAGE_DEEP_SCANLINE || storage == EXR_STORAGE_DEEP_TILED) return;
  exr_compression_t compression = EXR_COMPRESSION_NONE;
  if (const exr_result_t r = exr_get_compression(context, part, &compression); r != EXR_ERR_SUCCESS)
    throw refuse(r);
  if (double(rawBytes) > double(fileBytes) * maxExpansion(compression))
    throw InputError(where, "declares " + formatBytes(rawBytes) + " of pixels, more than its " +
                                std::to_string(fileBytes) +
                                " bytes can hold under its compression; the "
                                "header's data window does not match the file");
  if (storage != EXR_STORAGE_SCANLINE) return;
  uint64_t packed = 0;
  for (int64_t y = window.min.y; y <= window.max.y; y += std::max(chunkRows, 1)) {
    exr_chunk_info_t chunk{};
    if (const exr_result_t r = exr_read_scanline_chunk_info(context, part, int(y), &chunk);
        r != EXR_ERR_SUCCESS)
      throw InputError(where, "cannot locate the chunk of scanline " + std::to_string(y) +
                                  ": its offset table or leader is broken (a truncated file, or a header "
                                  "whose data window does not match the file)");
    packed += chunk.packed_size;
    if (chunk.data_offset > fileBytes || chunk.packed_size > fileBytes - chunk.data_offset ||
        packed > fileBytes)
      throw InputError(where, "the chunk of scanline " + std::to_string(y) + " lies past the end of the " +
                                  std::to_string(fileBytes) + "-byte file");
  }
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
  std::error_code sizeError;
  const uint64_t fileBytes = fs::file_size(file, sizeError);
  if (sizeError) throw IoError(where, "cannot read: " + sizeError.message());
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
    const int64_t width = int64_t(window.max.x) - window.min.x + 1,
                  height = int64_t(window.max.y) - window.min.y + 1;
    checkDeclaredSize(where, width, height, channels ? channels->num_channels : 0, chunkRows);
    uint64_t rawBytes = 0;  // every channel's samples as stored (a subsampled one has fewer)
    for (int c = 0; c < channels->num_channels; ++c) {
      const exr_attr_chlist_entry_t& channel = channels->entries[c];
      const int64_t xs = std::max(channel.x_sampling, 1), ys = std::max(channel.y_sampling, 1);
      rawBytes += uint64_t((width + xs - 1) / xs) * uint64_t((height + ys - 1) / ys) *
                  (channel.pixel_type == EXR_PIXEL_HALF ? 2u : 4u);
    }
    checkAgainstFile(context, part, where, fileBytes, rawBytes, storage, window, chunkRows, refuse);
  }
}

bool isHalf(const std::string& c) {
  return c == "R" || c == "G" || c == "B" || c == "A";
}

}  // namespace

void setExrThreads(int threads) {
  Imf::setGlobalThreadCount(threads);
}

void writeExr(const fs::path& file, const Image& image, const ExrMetadata& metadata) {
  Imf::Header header(image.width, image.height);
  header.compression() = Imf::ZIP_COMPRESSION;
  for (const auto& [key, value] : metadata.strings) header.insert(key, Imf::StringAttribute(value));
  for (const auto& [key, value] : metadata.floats) header.insert(key, Imf::FloatAttribute(value));
  for (const auto& [key, value] : metadata.sizes)
    header.insert(key, Imf::V2iAttribute(Imath::V2i(value.x, value.y)));
  for (const auto& [key, value] : metadata.ints) header.insert(key, Imf::IntAttribute(value));
  if (metadata.framesPerSecond > 0.0)
    Imf::addFramesPerSecond(header, framesPerSecond(metadata.framesPerSecond));
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
      // Compressed on OpenEXR's global thread pool, which the command sets to its --threads: each chunk
      // is compressed alone, so the bytes are the same for any count.
      Imf::OutputFile out(temporary.c_str(), header, Imf::globalThreadCount());
      out.setFrameBuffer(frame);
      out.writePixels(image.height);
    } catch (const std::exception& e) {
      throw IoError("cannot write " + file.string() + ": " + e.what());
    }
  });
}

namespace {

// libhairgen_images.so (image_module.h), loaded once, the first time an image needs OpenImageIO.
const ImageModule& imageModule() {
  static const ImageModule* module = nullptr;
  static std::string failure;
  static std::once_flag once;
  std::call_once(once, [] {
    std::vector<fs::path> places;
    std::error_code ec;
    const fs::path self = fs::read_symlink("/proc/self/exe", ec);
    if (!ec) places.push_back(self.parent_path() / "libhairgen_images.so");
    places.push_back(fs::path(HAIRGEN_IMAGE_MODULE));  // where the build put it
    for (const fs::path& place : places) {
      void* handle = ::dlopen(place.c_str(), RTLD_NOW | RTLD_LOCAL);
      if (!handle) {
        failure = oneLine(::dlerror());
        continue;
      }
      using Entry = const ImageModule* (*)();
      const auto entry = reinterpret_cast<Entry>(::dlsym(handle, "hairgen_image_module"));
      if (entry && std::string_view(entry()->build) == kImageModuleBuild) {
        module = entry();
        return;
      }
      failure = place.string() + " is not this hairgen's image module";
    }
  });
  if (!module)
    throw IoError(
        "cannot read images other than OpenEXR: hairgen's image module (libhairgen_images.so, "
        "beside the executable) did not load: " +
        failure);
  return *module;
}

// The first part of an EXR, every channel as float: R, G, B, A first, then the others in the file's
// order. The header has been checked (checkExrHeader), so nothing here allocates what it declares
// beyond what fits.
Image readExr(const fs::path& file, const FileLoc& where) {
  try {
    Imf::InputFile in(file.c_str());
    const Imath::Box2i window = in.header().dataWindow();
    Image image;
    image.width = window.max.x - window.min.x + 1;
    image.height = window.max.y - window.min.y + 1;
    std::vector<std::string> names;
    for (auto it = in.header().channels().begin(); it != in.header().channels().end(); ++it) {
      if (it.channel().xSampling != 1 || it.channel().ySampling != 1)
        throw InputError(where, "channel " + std::string(it.name()) +
                                    " is subsampled; hairgen reads full-resolution channels");
      names.push_back(it.name());
    }
    const auto rank = [](const std::string& n) {
      return n.size() == 1 ? std::min(std::string_view("RGBA").find(n[0]), size_t(4)) : size_t(4);
    };
    std::stable_sort(names.begin(), names.end(),
                     [&](const std::string& a, const std::string& b) { return rank(a) < rank(b); });
    const size_t pixels = size_t(image.width) * size_t(image.height);
    Imf::FrameBuffer frame;
    for (const std::string& name : names) {
      image.channels.push_back(name);
      image.planes.emplace_back(pixels);
      frame.insert(name, Imf::Slice::Make(Imf::FLOAT, image.planes.back().data(), window));
    }
    in.setFrameBuffer(frame);
    in.readPixels(window.min.y, window.max.y);
    return image;
  } catch (const InputError&) {
    throw;
  } catch (const std::exception& e) {
    throw InputError(where, "not a readable OpenEXR file: " + oneLine(e.what()));
  }
}

}  // namespace

Image readImage(const fs::path& file) {
  requireRegularFile(file);
  const FileLoc where{file.string(), 0};
  if (toLower(file.extension().string()) == ".exr") {
    checkExrHeader(file, where);
    return readExr(file, where);
  }
  Image image;
  std::string error;
  if (!imageModule().read(file.c_str(), kMaxImageSide, kMaxImageChannels, memoryBudget(), &image, &error))
    throw InputError(where, error);
  return image;
}

ImageHeader readImageHeader(const fs::path& file) {
  requireRegularFile(file);
  const FileLoc where{file.string(), 0};
  if (toLower(file.extension().string()) == ".exr") checkExrHeader(file, where);
  ImageHeader header;
  std::string error;
  if (!imageModule().header(file.c_str(), &header, &error)) throw InputError(where, error);
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
  png_image png{};
  png.version = PNG_IMAGE_VERSION;
  png.width = png_uint_32(image.width);
  png.height = png_uint_32(image.height);
  png.format = PNG_FORMAT_RGB;
  png_alloc_size_t bytes = 0;
  if (!png_image_write_to_memory(&png, nullptr, &bytes, 0, rgb.data(), 0, nullptr))
    throw IoError("cannot write " + file.string() + ": " + png.message);
  std::vector<unsigned char> encoded(bytes);
  if (!png_image_write_to_memory(&png, encoded.data(), &bytes, 0, rgb.data(), 0, nullptr))
    throw IoError("cannot write " + file.string() + ": " + png.message);
  writeFileAtomic(file, encoded.data(), bytes);
}

}  // namespace hairgen
