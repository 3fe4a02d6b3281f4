#include "libcore/render/readback.h"

#include <algorithm>
#include <cstring>
#include <memory>

#include <tbb/blocked_range2d.h>
#include <tbb/parallel_for.h>

#include "libcore/render/gl_context.h"

namespace hairgen {

namespace {

// A pixel-pack buffer the CPU maps to read (client storage: a GPU writes it in host memory).
struct PackBuffer {
  GLuint id = 0;
  size_t bytes = 0;
  explicit PackBuffer(size_t size) : bytes(size) {
    glCreateBuffers(1, &id);
    glNamedBufferStorage(id, static_cast<GLsizeiptr>(bytes), nullptr,
                         GL_MAP_READ_BIT | GL_CLIENT_STORAGE_BIT);
  }
  ~PackBuffer() { glDeleteBuffers(1, &id); }
  PackBuffer(const PackBuffer&) = delete;
  PackBuffer& operator=(const PackBuffer&) = delete;
};

// The context's pack buffer of at least `bytes` (one of its own without a GlContext): kept from frame
// to frame, replaced by a larger one when a readback needs more.
struct KeptPackBuffer {
  std::unique_ptr<PackBuffer> buffer;
};

constexpr GLenum kChannelFormats[4] = {GL_RED, GL_GREEN, GL_BLUE, GL_ALPHA};

// Rows copied per task: a 1080p plane's rows are 7.7 KB, so 64 rows are half a megabyte.
constexpr size_t kRowsPerTask = 64;

}  // namespace

void readPlanes(const std::vector<PlaneRead>& reads, ReadbackLayout layout) {
  const bool wholeTextures =
      layout == ReadbackLayout::kAuto ? softwareRasteriser() : layout == ReadbackLayout::kWholeTextures;
  struct Slice {
    const Texture* texture;
    GLenum format;
    size_t offset, components;  // floats a texel in the buffer
  };
  std::vector<Slice> slices;
  std::vector<std::pair<size_t, size_t>> sources;  // per read: its slice, its component there
  size_t total = 0;
  for (const PlaneRead& r : reads) {
    auto same =
        std::find_if(slices.begin(), slices.end(), [&](const Slice& s) { return s.texture == r.texture; });
    if (!wholeTextures || same == slices.end()) {
      const size_t components = wholeTextures ? 4 : 1;
      slices.push_back({r.texture, wholeTextures ? GL_RGBA : kChannelFormats[r.channel], total, components});
      total += size_t(r.texture->width) * size_t(r.texture->height) * components * sizeof(float);
      same = slices.end() - 1;
    }
    sources.emplace_back(size_t(same - slices.begin()), wholeTextures ? size_t(r.channel) : 0);
  }
  if (total == 0) return;
  std::unique_ptr<PackBuffer> own;
  PackBuffer* buffer = nullptr;
  if (GlContext* gl = GlContext::current()) {
    KeptPackBuffer& kept =
        gl->kept<KeptPackBuffer>("readback", [] { return std::make_unique<KeptPackBuffer>(); });
    if (!kept.buffer || kept.buffer->bytes < total) {
      kept.buffer.reset();  // the smaller one first: both are never held at once
      kept.buffer = std::make_unique<PackBuffer>(total);
    }
    buffer = kept.buffer.get();
  } else {
    own = std::make_unique<PackBuffer>(total);
    buffer = own.get();
  }
  glBindBuffer(GL_PIXEL_PACK_BUFFER, buffer->id);
  glPixelStorei(GL_PACK_ALIGNMENT, 4);
  for (const Slice& s : slices) {
    const size_t bytes = size_t(s.texture->width) * size_t(s.texture->height) * s.components * sizeof(float);
    glGetTextureImage(s.texture->id, 0, s.format, GL_FLOAT, static_cast<GLsizei>(bytes),
                      reinterpret_cast<void*>(uintptr_t(s.offset)));
  }
  glBindBuffer(GL_PIXEL_PACK_BUFFER, 0);
  checkGl("reading the images into a pixel-pack buffer");
  const auto* mapped = static_cast<const unsigned char*>(
      glMapNamedBufferRange(buffer->id, 0, static_cast<GLsizeiptr>(total), GL_MAP_READ_BIT));
  if (!mapped) renderFailure("could not map the pixel-pack buffer of " + std::to_string(total) + " bytes");
  size_t rows = 0;
  for (const PlaneRead& r : reads) {
    r.plane->resize(size_t(r.texture->width) * size_t(r.texture->height));
    rows = std::max(rows, size_t(r.texture->height));
  }
  // Plane by row block: each block's rows turned top to bottom.
  tbb::parallel_for(tbb::blocked_range2d<size_t>(0, reads.size(), 1, 0, rows, kRowsPerTask),
                    [&](const tbb::blocked_range2d<size_t>& range) {
                      for (size_t i = range.rows().begin(); i < range.rows().end(); ++i) {
                        const PlaneRead& r = reads[i];
                        const Slice& s = slices[sources[i].first];
                        const size_t w = size_t(r.texture->width), h = size_t(r.texture->height);
                        const size_t end = std::min(range.cols().end(), h), n = s.components;
                        for (size_t y = range.cols().begin(); y < end; ++y) {
                          const auto* from = reinterpret_cast<const float*>(mapped + s.offset) + y * w * n;
                          float* to = r.plane->data() + (h - 1 - y) * w;
                          if (n == 1) {
                            std::memcpy(to, from, w * sizeof(float));
                            continue;
                          }
                          from += sources[i].second;
                          for (size_t x = 0; x < w; ++x) to[x] = from[x * n];
                        }
                      }
                    });
  if (!glUnmapNamedBuffer(buffer->id)) renderFailure("the pixel-pack buffer's contents were lost while read");
}

}  // namespace hairgen
