#include "libcore/render/readback.h"

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

void readPlanes(const std::vector<PlaneRead>& reads) {
  std::vector<size_t> offsets;
  size_t total = 0;
  for (const PlaneRead& r : reads) {
    offsets.push_back(total);
    total += size_t(r.texture->width) * size_t(r.texture->height) * sizeof(float);
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
  for (size_t i = 0; i < reads.size(); ++i) {
    const PlaneRead& r = reads[i];
    const size_t bytes = size_t(r.texture->width) * size_t(r.texture->height) * sizeof(float);
    glGetTextureImage(r.texture->id, 0, kChannelFormats[r.channel], GL_FLOAT, static_cast<GLsizei>(bytes),
                      reinterpret_cast<void*>(uintptr_t(offsets[i])));
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
  // Plane by row block: each block's rows flipped into place.
  tbb::parallel_for(tbb::blocked_range2d<size_t>(0, reads.size(), 1, 0, rows, kRowsPerTask),
                    [&](const tbb::blocked_range2d<size_t>& range) {
                      for (size_t i = range.rows().begin(); i < range.rows().end(); ++i) {
                        const PlaneRead& r = reads[i];
                        const size_t w = size_t(r.texture->width), h = size_t(r.texture->height);
                        const size_t end = std::min(range.cols().end(), h);
                        for (size_t y = range.cols().begin(); y < end; ++y)
                          std::memcpy(r.plane->data() + (h - 1 - y) * w,
                                      mapped + offsets[i] + y * w * sizeof(float), w * sizeof(float));
                      }
                    });
  if (!glUnmapNamedBuffer(buffer->id)) renderFailure("the pixel-pack buffer's contents were lost while read");
}

}  // namespace hairgen
