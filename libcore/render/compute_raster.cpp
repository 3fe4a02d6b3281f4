#include "libcore/render/compute_raster.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>

#include "glsl/embedded_glsl.h"
#include "libcore/render/shader_interface.h"

namespace hairgen {

namespace {

// A slab's lists at most (16 bytes a fragment), whatever larger buffer the device allows: the camera's
// fragments of a 1080p image of 150,000 strands take ~0.5 GB in one slab.
constexpr size_t kSlabBytes = size_t(1) << 30;

// The text of a compute stage: the int64 extension, `defines`, the GLSL constants, then a pass over the
// segments (`perSegment`: the raster's constants and glsl/raster_segment.glsl) or over texels, `body`.
StageSource computeStage(const char* body, bool perSegment, const std::string& defines = "") {
  StageSource s;
  s.text = "#version 450 core\n#extension GL_ARB_gpu_shader_int64 : require\n" + defines + glslConstants();
  if (perSegment)
    s.text += "const int64_t kSubTexel = " + std::to_string(kSubTexel) + "l;\n" +
              "const int64_t kWidthUnit = " + std::to_string(kWidthUnit) + "l;\n" +
              "const int kRasterVertexBinding = 0;\nconst int kRasterSegmentBinding = 1;\n" +
              glsl::kRasterSegment;
  s.text += std::string("#line 1\n") + body;
  return s;
}

// Enough groups of `size` invocations for `invocations`, in rows of at most 65,535 groups (the least
// any device allows in x); the stages skip what lies past the end.
void dispatch(size_t invocations, size_t size) {
  const size_t groups = (invocations + size - 1) / size;
  if (groups == 0) return;
  const size_t x = std::min<size_t>(groups, 65535), y = (groups + x - 1) / x;
  glDispatchCompute(GLuint(x), GLuint(y), 1);
}

GLint maxStorageBlock() {
  GLint size = 0;
  glGetIntegerv(GL_MAX_SHADER_STORAGE_BLOCK_SIZE, &size);
  return size;
}

void setRaster(const Program& p, const DeviceProjection& hair) {
  hair.vertices.bind(0);
  hair.segmentList.bind(1);
  glUniform2i(p.loc("uRasterSize"), hair.width, hair.height);
  glUniform1ui(p.loc("uSegmentCount"), GLuint(hair.segments));
}

void drawSegments(const DeviceProjection& hair) {
  dispatch(hair.segments, 256);
  glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
}

}  // namespace

bool fitsDevice(size_t bytes) {
  return bytes <= size_t(maxStorageBlock());
}

bool computeRasterAvailable() {
  GLint n = 0;
  glGetIntegerv(GL_NUM_EXTENSIONS, &n);
  for (GLint i = 0; i < n; ++i)
    if (std::strcmp(reinterpret_cast<const char*>(glGetStringi(GL_EXTENSIONS, GLuint(i))),
                    "GL_ARB_gpu_shader_int64") == 0)
      return true;
  return false;
}

DeviceBuffer::DeviceBuffer(size_t size, const void* data) : bytes(std::max<size_t>(size, 4)) {
  glCreateBuffers(1, &id);
  glNamedBufferStorage(id, GLsizeiptr(bytes), size ? data : nullptr, 0);
}

DeviceBuffer::~DeviceBuffer() {
  glDeleteBuffers(1, &id);
}

void DeviceBuffer::clear(uint32_t word) const {
  glClearNamedBufferData(id, GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, &word);
}

template <class T>
std::vector<T> DeviceBuffer::read(size_t count) const {
  std::vector<T> out(count);
  if (count) glGetNamedBufferSubData(id, 0, GLsizeiptr(count * sizeof(T)), out.data());
  return out;
}

raster::Projection DeviceProjection::read() const {
  raster::Projection p;
  p.width = width;
  p.height = height;
  p.vertices = vertices.read<raster::Vertex>(vertices.bytes / sizeof(raster::Vertex));
  p.segments = segmentList.read<uint32_t>(segments);
  return p;
}

DeviceProjection::DeviceProjection(const raster::Projection& p)
    : width(p.width),
      height(p.height),
      segments(p.segments.size()),
      vertices(p.vertices.size() * sizeof(raster::Vertex), p.vertices.data()),
      segmentList(p.segments.size() * sizeof(uint32_t), p.segments.data()) {
  static_assert(sizeof(raster::Vertex) == 16);
}

void computeLightMaps(const DeviceProjection& hair, const glm::dvec4& layerSizes, double strandOpacity,
                      float background, const Texture& start, const Texture& opacity,
                      HairLightMaps* integers) {
  const size_t texels = size_t(hair.width) * size_t(hair.height);
  DeviceBuffer begins(texels * sizeof(int32_t)), layers(texels * 4 * sizeof(uint32_t)),
      overflow(texels * sizeof(uint32_t));
  begins.clear(uint32_t(std::numeric_limits<int32_t>::max()));
  layers.clear(0);
  overflow.clear(0);
  {
    const Program p(computeStage(glsl::kLightStart, true, "#define ACROSS_TENT\n"), "light start");
    p.use();
    setRaster(p, hair);
    begins.bind(2);
    drawSegments(hair);
  }
  {
    const Program p(computeStage(glsl::kLightLayers, true, "#define ACROSS_TENT\n"), "light layers");
    p.use();
    setRaster(p, hair);
    // As light_maps.cpp: each layer's far end from where the hair begins; a depth behind it is below
    // 2^31 units, so an end past that is as good as INT32_MAX.
    GLint ends[3];
    double cumulative = 0.0;
    for (int k = 0; k < 3; ++k) {
      cumulative += layerSizes[k];
      ends[k] = GLint(std::clamp<double>(std::llround(cumulative / kDepthUnit), INT32_MIN, INT32_MAX));
    }
    glUniform3iv(p.loc("uLayerEnds"), 1, ends);
    begins.bind(2);
    layers.bind(3);
    overflow.bind(4);
    drawSegments(hair);
  }
  {
    const Program p(computeStage(glsl::kLightFinish, false), "light finish");
    p.use();
    glUniform1i(p.loc("uSize"), hair.width);
    glUniform1f(p.loc("uBackground"), background);
    glUniform1d(p.loc("uDepthUnit"), kDepthUnit);
    glUniform1d(p.loc("uOpacityScale"), strandOpacity / double(kCoverageOne));
    begins.bind(2);
    layers.bind(3);
    overflow.bind(4);
    glBindImageTexture(0, start.id, 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_R32F);
    glBindImageTexture(1, opacity.id, 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA32F);
    dispatch(texels, 256);
    glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT |
                    GL_BUFFER_UPDATE_BARRIER_BIT | GL_FRAMEBUFFER_BARRIER_BIT |
                    GL_TEXTURE_UPDATE_BARRIER_BIT);
    glBindImageTexture(0, 0, 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_R32F);
    glBindImageTexture(1, 0, 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA32F);
  }
  checkGl("the light's maps on the device");
  if (!integers) return;
  integers->size = hair.width;
  integers->start = begins.read<int32_t>(texels);
  integers->layers = layers.read<glm::uvec4>(texels);
}

CameraFragments DeviceFragments::read(int width, int height) const {
  const size_t pixels = size_t(width) * size_t(height);
  CameraFragments out;
  out.width = width;
  out.height = height;
  out.first = first->read<uint32_t>(pixels + 1);
  out.words = words->read<uint32_t>(3 * count);
  out.tail = tail->read<uint32_t>(pixels);
  return out;
}

std::optional<DeviceFragments> computeCameraFragments(const DeviceProjection& hair, int kept,
                                                      const Texture* opaque, size_t slabBytes) {
  kept = std::clamp(kept, 1, 255);
  const size_t width = size_t(hair.width), pixels = width * size_t(hair.height);
  if (!fitsDevice(pixels * sizeof(uint32_t))) return std::nullopt;
  const std::string keptDefine = "#define KEPT " + std::to_string(kept) + "\n";
  auto useOpaque = [&](const Program& p) {
    glUniform1i(p.loc("uHasOpaque"), opaque ? 1 : 0);
    glUniform1d(p.loc("uDepthUnit"), kDepthUnit);
    if (opaque) glBindTextureUnit(kUnitSubpixelData, opaque->id);
  };
  // Each pixel's fragments counted.
  DeviceBuffer counts(pixels * sizeof(uint32_t));
  counts.clear(0);
  {
    const Program p(computeStage(glsl::kCameraCount, true), "camera count");
    p.use();
    setRaster(p, hair);
    useOpaque(p);
    counts.bind(2);
    drawSegments(hair);
  }
  const std::vector<uint32_t> count = counts.read<uint32_t>(pixels);
  // The rows in slabs whose lists fit a buffer; each pixel's list's place within its slab, and its kept
  // fragments' place among every pixel's (at most min(count, kept) of them).
  const size_t slabFragments =
      std::min<size_t>(slabBytes ? slabBytes : kSlabBytes, size_t(maxStorageBlock())) /
      (4 * sizeof(uint32_t));
  std::vector<uint32_t> offsets(pixels), keepAt(pixels);
  std::vector<int> slabRows{0};
  size_t slabLargest = 0, inSlab = 0;
  uint64_t keptBound = 0;
  for (int row = 0; row < hair.height; ++row) {
    uint64_t rowFragments = 0;
    for (size_t p = size_t(row) * width; p < size_t(row + 1) * width; ++p) rowFragments += count[p];
    if (rowFragments > slabFragments) return std::nullopt;
    if (inSlab + rowFragments > slabFragments) {
      slabRows.push_back(row);
      inSlab = 0;
    }
    for (size_t p = size_t(row) * width; p < size_t(row + 1) * width; ++p) {
      offsets[p] = uint32_t(inSlab);
      inSlab += count[p];
      keepAt[p] = uint32_t(keptBound);
      keptBound += std::min<uint32_t>(count[p], uint32_t(kept));
    }
    slabLargest = std::max(slabLargest, inSlab);
    if (!fitsDevice(keptBound * 3 * sizeof(uint32_t))) return std::nullopt;
  }
  slabRows.push_back(hair.height);
  const DeviceBuffer offsetBuffer(pixels * sizeof(uint32_t), offsets.data()),
      keepAtBuffer(pixels * sizeof(uint32_t), keepAt.data());
  DeviceBuffer cursors(pixels * sizeof(uint32_t)), lists(slabLargest * 4 * sizeof(uint32_t)),
      keptCounts(pixels * sizeof(uint32_t)), staging(size_t(keptBound) * 3 * sizeof(uint32_t));
  cursors.clear(0);
  auto tails = std::make_unique<DeviceBuffer>(pixels * sizeof(uint32_t));
  const Program fill(computeStage(glsl::kCameraFill, true), "camera fill");
  const Program keep(computeStage(glsl::kCameraKeep, false, keptDefine), "camera keep");
  for (size_t s = 0; s + 1 < slabRows.size(); ++s) {
    if (slabRows[s] == slabRows[s + 1]) continue;
    fill.use();
    setRaster(fill, hair);
    useOpaque(fill);
    glUniform1i(fill.loc("uRowLo"), slabRows[s]);
    glUniform1i(fill.loc("uRowHi"), slabRows[s + 1]);
    offsetBuffer.bind(2);
    cursors.bind(3);
    lists.bind(4);
    drawSegments(hair);
    keep.use();
    const size_t lo = size_t(slabRows[s]) * width, hi = size_t(slabRows[s + 1]) * width;
    glUniform1ui(keep.loc("uPixelLo"), GLuint(lo));
    glUniform1ui(keep.loc("uPixelHi"), GLuint(hi));
    glUniform1d(keep.loc("uDepthUnit"), kDepthUnit);
    offsetBuffer.bind(2);
    counts.bind(3);
    lists.bind(4);
    keptCounts.bind(5);
    tails->bind(6);
    keepAtBuffer.bind(7);
    staging.bind(8);
    dispatch(hi - lo, 64);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
  }
  // Each pixel's first kept fragment: the kept counts summed.
  const std::vector<uint32_t> keptCount = keptCounts.read<uint32_t>(pixels);
  std::vector<uint32_t> first(pixels + 1);
  uint32_t total = 0;
  for (size_t p = 0; p < pixels; ++p) {
    first[p] = total;
    total += keptCount[p];
  }
  first[pixels] = total;
  DeviceFragments out;
  out.count = total;
  out.first = std::make_unique<DeviceBuffer>(first.size() * sizeof(uint32_t), first.data());
  out.words = std::make_unique<DeviceBuffer>(size_t(total) * 3 * sizeof(uint32_t));
  out.tail = std::move(tails);
  {
    const Program p(computeStage(glsl::kCameraPack, false), "camera pack");
    p.use();
    glUniform1ui(p.loc("uPixels"), GLuint(pixels));
    out.first->bind(5);
    out.words->bind(6);
    keepAtBuffer.bind(7);
    staging.bind(8);
    dispatch(pixels, 256);
  }
  glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
  checkGl("the camera's fragments on the device");
  return out;
}

}  // namespace hairgen
