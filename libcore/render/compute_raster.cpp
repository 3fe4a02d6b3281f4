#include "libcore/render/compute_raster.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <string>

#include "glsl/embedded_glsl.h"
#include "libcore/render/gl_context.h"
#include "libcore/render/shader_interface.h"

namespace hairgen {

namespace {

// llvmpipe (Mesa 22.3's gallivm) ends every loop of a shader invocation once the invocation has run
// 65,535 loop iterations in all, silently: on a software rasteriser the passes are used only where each
// invocation stays well inside that (withinLoopBudget; the keeping pass's sort of a pixel's n fragments,
// about 2 n log2 n steps, and its n × (KEPT + 1)), the CPU's rasteriser elsewhere.
constexpr uint64_t kSoftwareLoopBudget = 40000;

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

GLint64 maxStorageBlock() {
  GLint64 size = 0;
  glGetInteger64v(GL_MAX_SHADER_STORAGE_BLOCK_SIZE, &size);
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

namespace {

// Whether the device's floating point gives the CPU's bits where the passes use it (glsl/raster_probe.glsl):
// GLSL leaves double arithmetic's rounding and a double sqrt's precision to the device, so they are
// tried on depths and squares chosen to catch a device that rounds otherwise, before any pass relies
// on them.
bool floatingPointAgrees() {
  std::vector<int32_t> depths = {0, 1, 2, 3, 999999, 1000000, 1000001, 123456789, 2000000000, INT32_MAX};
  std::vector<uint64_t> squares;
  uint64_t state = 0x9E3779B97F4A7C15ull;  // a fixed sequence (splitmix64), the same every run
  auto next = [&] {
    uint64_t z = (state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  };
  while (depths.size() < 4096) depths.push_back(int32_t(next() >> 33));
  for (uint64_t k : {uint64_t(1), uint64_t(255), uint64_t(65535), uint64_t(94906265), uint64_t(1) << 26})
    for (uint64_t n : {k * k - 1, k * k, k * k + k, k * k + k + 1}) squares.push_back(n);
  while (squares.size() < 4096) squares.push_back(next() >> (12 + next() % 40));
  const DeviceBuffer depthIn(depths.size() * sizeof(int32_t), depths.data()),
      squareIn(squares.size() * sizeof(uint64_t), squares.data()), depthOut(depths.size() * sizeof(uint32_t)),
      squareOut(squares.size() * sizeof(uint64_t));
  const Program p(computeStage(glsl::kRasterProbe, true), "raster probe");
  p.use();
  glUniform1d(p.loc("uDepthUnit"), kDepthUnit);
  glUniform1ui(p.loc("uCount"), GLuint(depths.size()));
  depthIn.bind(2);
  squareIn.bind(3);
  depthOut.bind(4);
  squareOut.bind(5);
  dispatch(depths.size(), 256);
  glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
  const std::vector<uint32_t> metres = depthOut.read<uint32_t>(depths.size());
  const std::vector<uint64_t> roots = squareOut.read<uint64_t>(squares.size());
  for (size_t i = 0; i < depths.size(); ++i)
    if (metres[i] != std::bit_cast<uint32_t>(float(double(depths[i]) * kDepthUnit))) return false;
  for (size_t i = 0; i < squares.size(); ++i)
    if (roots[i] != raster::roundedSqrt(squares[i])) return false;
  return true;
}

// The answer kept by the context, so a sequence probes once.
struct ProbeResult {
  bool agrees = false;
};

}  // namespace

bool withinLoopBudget(const raster::Projection& p) {
  for (const uint32_t first : p.segments) {
    const raster::Vertex &a = p.vertices[first], &b = p.vertices[size_t(first) + 1];
    const int64_t du = std::max(std::abs(int64_t(b.x) - a.x), std::abs(int64_t(b.y) - a.y));
    // The columns along the major axis, and per column the texels across a piece's cross-section (at
    // most its width over cos 45°, a tent's texel more either side).
    const uint64_t along = uint64_t(du / kSubTexel + 2);
    const uint64_t across = uint64_t(std::max(a.width, b.width)) * 3 / (2 * uint64_t(kWidthUnit)) + 4;
    if (along * (across + 1) > kSoftwareLoopBudget) return false;
  }
  return true;
}

bool computeRasterAvailable() {
  if (!hasGlExtension("GL_ARB_gpu_shader_int64")) return false;
  GlContext* gl = GlContext::current();
  if (!gl) return floatingPointAgrees();
  return gl
      ->kept<ProbeResult>("compute raster probe",
                          [] {
                            auto result = std::make_unique<ProbeResult>();
                            result->agrees = floatingPointAgrees();
                            return result;
                          })
      .agrees;
}

namespace {

// The light's passes (computeLightMaps).
struct LightPasses {
  Program starts{computeStage(glsl::kLightStart, true, "#define ACROSS_TENT\n"), "light start"};
  Program sums{computeStage(glsl::kLightLayers, true, "#define ACROSS_TENT\n"), "light layers"};
  Program finish{computeStage(glsl::kLightFinish, false), "light finish"};
};

// The camera's passes for `kept` fragments a pixel, 1-255 (computeCameraFragments).
struct CameraPasses {
  explicit CameraPasses(int kept)
      : keep(computeStage(glsl::kCameraKeep, false, "#define KEPT " + std::to_string(kept) + "\n"),
             "camera keep") {}
  Program count{computeStage(glsl::kCameraCount, true), "camera count"};
  PrefixSum prefixSum;
  Program rowTotals{computeStage(glsl::kCameraRows, false), "camera rows"};
  Program fill{computeStage(glsl::kCameraFill, true), "camera fill"};
  Program keep;
  Program pack{computeStage(glsl::kCameraPack, false), "camera pack"};
};

struct PassesBuilt {
  std::string failure;
};

}  // namespace

std::string computePassesFailure(int kept) {
  kept = std::clamp(kept, 1, 255);
  auto build = [&] {
    auto built = std::make_unique<PassesBuilt>();
    try {
      // As the passes make them, so theirs are these, kept in the context.
      const LightPasses light;
      const CameraPasses camera(kept);
    } catch (const Error& e) {
      const std::string what = e.what(), prefix = "rendering: ";  // renderFailure's
      built->failure = what.starts_with(prefix) ? what.substr(prefix.size()) : what;
    }
    return built;
  };
  GlContext* gl = GlContext::current();
  if (!gl) return build()->failure;
  return gl->kept<PassesBuilt>("compute raster passes, kept " + std::to_string(kept), build).failure;
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
std::vector<T> DeviceBuffer::read(size_t count, size_t first) const {
  std::vector<T> out(count);
  if (count)
    glGetNamedBufferSubData(id, GLintptr(first * sizeof(T)), GLsizeiptr(count * sizeof(T)), out.data());
  return out;
}

namespace {

std::string scanDefines(const char* pass) {
  return std::string("#define ") + pass + "\n#define SCAN_LANES " + std::to_string(PrefixSum::kLanes) +
         "\n#define SCAN_PER_INVOCATION " + std::to_string(PrefixSum::kPerInvocation) + "\n";
}

}  // namespace

PrefixSum::PrefixSum()
    : blocks_(computeStage(glsl::kPrefixSum, false, scanDefines("SCAN_BLOCKS")), "prefix sum"),
      add_(computeStage(glsl::kPrefixSum, false, scanDefines("ADD_BLOCKS")), "prefix sum's add") {}

void PrefixSum::operator()(const DeviceBuffer& in, size_t count, const DeviceBuffer& out, uint32_t limit,
                           const DeviceBuffer* deepest) const {
  const size_t sums = count + 1, blocks = (sums + kBlock - 1) / kBlock;
  const DeviceBuffer blockSums(blocks * sizeof(uint32_t));
  blocks_.use();
  glUniform1ui(blocks_.loc("uSums"), GLuint(sums));
  glUniform1ui(blocks_.loc("uInputs"), GLuint(count));
  glUniform1ui(blocks_.loc("uLimit"), limit);
  glUniform1i(blocks_.loc("uDeepest"), deepest ? 1 : 0);
  in.bind(0);
  out.bind(1);
  blockSums.bind(2);
  if (deepest) deepest->bind(3);
  dispatch(blocks * kLanes, kLanes);
  glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
  if (blocks == 1) return;  // the block's sums are the sums
  // Each block's place among the blocks: the blocks' totals summed alike (a level a kBlock-th the size).
  const DeviceBuffer places((blocks + 1) * sizeof(uint32_t));
  (*this)(blockSums, blocks, places);
  add_.use();
  glUniform1ui(add_.loc("uSums"), GLuint(sums));
  out.bind(1);
  places.bind(2);
  dispatch(sums, 256);
  glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
}

raster::Projection DeviceProjection::read(DeviceTimer* timer) const {
  const DeviceTimer::Transfer timed(timer, "camera_projection_read",
                                    vertices.bytes + segments * sizeof(uint32_t));
  raster::Projection p;
  p.width = width;
  p.height = height;
  p.vertices = vertices.read<raster::Vertex>(vertices.bytes / sizeof(raster::Vertex));
  p.segments = segmentList.read<uint32_t>(segments);
  return p;
}

namespace {

// A buffer holding `bytes` of `data`, its upload timed as `transfer`.
DeviceBuffer uploaded(const void* data, size_t bytes, DeviceTimer* timer, const char* transfer) {
  const DeviceTimer::Transfer timed(timer, transfer, bytes);
  return DeviceBuffer(bytes, data);
}

}  // namespace

DeviceProjection::DeviceProjection(const raster::Projection& p, DeviceTimer* timer, const char* upload)
    : width(p.width),
      height(p.height),
      segments(p.segments.size()),
      vertices(uploaded(p.vertices.data(), p.vertices.size() * sizeof(raster::Vertex), timer, upload)),
      segmentList(uploaded(p.segments.data(), p.segments.size() * sizeof(uint32_t), timer, upload)) {
  static_assert(sizeof(raster::Vertex) == 16);
}

void computeLightMaps(const DeviceProjection& hair, const glm::dvec4& layerSizes, double strandOpacity,
                      float background, const Texture& start, const Texture& opacity, HairLightMaps* integers,
                      DeviceTimer* timer) {
  const size_t texels = size_t(hair.width) * size_t(hair.height);
  const LightPasses passes;
  const Program &starts = passes.starts, &sums = passes.sums, &finish = passes.finish;
  DeviceBuffer begins(texels * sizeof(int32_t)), layers(texels * 4 * sizeof(uint32_t)),
      overflow(texels * sizeof(uint32_t));
  {
    const DeviceTimer::Pass timed(timer, "light_start");
    begins.clear(uint32_t(std::numeric_limits<int32_t>::max()));
    starts.use();
    setRaster(starts, hair);
    begins.bind(2);
    drawSegments(hair);
  }
  {
    const DeviceTimer::Pass timed(timer, "light_layers");
    layers.clear(0);
    overflow.clear(0);
    sums.use();
    setRaster(sums, hair);
    // A depth behind where the hair begins is below 2^31 units, so an end past that is as good as
    // INT32_MAX (the uniform's largest).
    const std::array<int64_t, 3> far = layerEnds(layerSizes);
    GLint ends[3];
    for (int k = 0; k < 3; ++k) ends[k] = GLint(std::clamp<int64_t>(far[k], INT32_MIN, INT32_MAX));
    glUniform3iv(sums.loc("uLayerEnds"), 1, ends);
    begins.bind(2);
    layers.bind(3);
    overflow.bind(4);
    drawSegments(hair);
  }
  {
    const DeviceTimer::Pass timed(timer, "light_finish");
    finish.use();
    glUniform1i(finish.loc("uSize"), hair.width);
    glUniform1f(finish.loc("uBackground"), background);
    glUniform1d(finish.loc("uDepthUnit"), kDepthUnit);
    glUniform1d(finish.loc("uOpacityScale"), strandOpacity / double(kCoverageOne));
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
                                                      const Texture* opaque, size_t slabBytes,
                                                      DeviceTimer* timer) {
  kept = std::clamp(kept, 1, 255);
  const size_t width = size_t(hair.width), pixels = width * size_t(hair.height), rows = size_t(hair.height);
  if (!fitsDevice((pixels + 1) * sizeof(uint32_t))) return std::nullopt;
  const CameraPasses passes(kept);
  const Program &count = passes.count, &rowTotals = passes.rowTotals, &fill = passes.fill,
                &keep = passes.keep, &pack = passes.pack;
  const PrefixSum& prefixSum = passes.prefixSum;
  auto useOpaque = [&](const Program& p) {
    glUniform1i(p.loc("uHasOpaque"), opaque ? 1 : 0);
    glUniform1d(p.loc("uDepthUnit"), kDepthUnit);
    if (opaque) glBindTextureUnit(kUnitSubpixelData, opaque->id);
  };
  // Each pixel's fragments counted.
  DeviceBuffer counts(pixels * sizeof(uint32_t));
  {
    const DeviceTimer::Pass timed(timer, "camera_count");
    counts.clear(0);
    count.use();
    setRaster(count, hair);
    useOpaque(count);
    counts.bind(2);
    drawSegments(hair);
  }
  // Each pixel's list's place among every pixel's, and its kept fragments' (at most min(count, kept)
  // of them); per row where both begin, and the deepest pixel's count, for the host.
  DeviceBuffer offsets((pixels + 1) * sizeof(uint32_t)), keepAt((pixels + 1) * sizeof(uint32_t)),
      totals((1 + 2 * (rows + 1)) * sizeof(uint32_t));
  {
    const DeviceTimer::Pass timed(timer, "camera_scan");
    totals.clear(0);
    prefixSum(counts, pixels, offsets, UINT32_MAX, &totals);
    prefixSum(counts, pixels, keepAt, uint32_t(kept));
    rowTotals.use();
    glUniform1ui(rowTotals.loc("uWidth"), GLuint(width));
    glUniform1ui(rowTotals.loc("uRows"), GLuint(rows));
    offsets.bind(0);
    keepAt.bind(1);
    totals.bind(2);
    dispatch(rows + 1, 256);
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
  }
  std::vector<uint32_t> rowStarts;
  {
    const DeviceTimer::Transfer timed(timer, "camera_totals_read", totals.bytes);
    rowStarts = totals.read<uint32_t>(1 + 2 * (rows + 1));
  }
  const uint64_t deepest = rowStarts[0];
  if (softwareRasteriser() &&
      deepest * (uint64_t(kept) + 1 + 2 * uint64_t(std::bit_width(deepest))) > kSoftwareLoopBudget)
    return std::nullopt;
  // A row's fragments are then below 2^32, and the differences of the sums (modulo 2^32) exact.
  if (deepest * width > UINT32_MAX) return std::nullopt;
  auto listsAt = [&](size_t row) { return rowStarts[1 + 2 * row]; };
  auto keptAt = [&](size_t row) { return rowStarts[2 + 2 * row]; };
  // The rows in slabs whose lists fit a buffer.
  const size_t slabFragments =
      std::min<size_t>(slabBytes ? slabBytes : kSlabBytes, size_t(maxStorageBlock())) /
      (4 * sizeof(uint32_t));
  std::vector<size_t> slabRows{0};
  size_t slabLargest = 0, inSlab = 0;
  uint64_t keptBound = 0;
  for (size_t row = 0; row < rows; ++row) {
    const size_t rowFragments = uint32_t(listsAt(row + 1) - listsAt(row));
    if (rowFragments > slabFragments) return std::nullopt;
    if (inSlab + rowFragments > slabFragments) {
      slabRows.push_back(row);
      inSlab = 0;
    }
    inSlab += rowFragments;
    slabLargest = std::max(slabLargest, inSlab);
    keptBound += uint32_t(keptAt(row + 1) - keptAt(row));
  }
  if (keptBound > UINT32_MAX || !fitsDevice(keptBound * 3 * sizeof(uint32_t))) return std::nullopt;
  slabRows.push_back(rows);
  // Kept: each pixel's kept count, and after them the keeping pass's fault word.
  DeviceBuffer cursors(pixels * sizeof(uint32_t)), lists(slabLargest * 4 * sizeof(uint32_t)),
      keptCounts((pixels + 1) * sizeof(uint32_t)), staging(size_t(keptBound) * 3 * sizeof(uint32_t));
  cursors.clear(0);
  keptCounts.clear(0);
  auto tails = std::make_unique<DeviceBuffer>(pixels * sizeof(uint32_t));
  for (size_t s = 0; s + 1 < slabRows.size(); ++s) {
    if (slabRows[s] == slabRows[s + 1]) continue;
    const size_t lo = slabRows[s] * width, hi = slabRows[s + 1] * width;
    const uint32_t slabFirst = listsAt(slabRows[s]);
    {
      const DeviceTimer::Pass timed(timer, "camera_fill");
      fill.use();
      setRaster(fill, hair);
      useOpaque(fill);
      glUniform1i(fill.loc("uRowLo"), GLint(slabRows[s]));
      glUniform1i(fill.loc("uRowHi"), GLint(slabRows[s + 1]));
      glUniform1ui(fill.loc("uSlabFirst"), slabFirst);
      offsets.bind(2);
      cursors.bind(3);
      lists.bind(4);
      counts.bind(5);
      drawSegments(hair);
    }
    {
      const DeviceTimer::Pass timed(timer, "camera_keep");
      keep.use();
      glUniform1ui(keep.loc("uPixelLo"), GLuint(lo));
      glUniform1ui(keep.loc("uPixelHi"), GLuint(hi));
      glUniform1ui(keep.loc("uSlabFirst"), slabFirst);
      glUniform1ui(keep.loc("uFault"), GLuint(pixels));
      glUniform1d(keep.loc("uDepthUnit"), kDepthUnit);
      offsets.bind(0);
      counts.bind(1);
      lists.bind(2);
      keptCounts.bind(3);
      tails->bind(4);
      keepAt.bind(5);
      staging.bind(6);
      cursors.bind(7);
      dispatch(hi - lo, 64);
      glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
    }
  }
  // Each pixel's first kept fragment: the kept counts' prefix sum (the last word the total).
  DeviceFragments out;
  out.first = std::make_unique<DeviceBuffer>((pixels + 1) * sizeof(uint32_t));
  {
    const DeviceTimer::Pass timed(timer, "camera_first");
    prefixSum(keptCounts, pixels, *out.first);
  }
  uint32_t fault = 0;
  {
    const DeviceTimer::Transfer timed(timer, "camera_kept_read", 2 * sizeof(uint32_t));
    fault = keptCounts.read<uint32_t>(1, pixels)[0];
    out.count = out.first->read<uint32_t>(1, pixels)[0];
  }
  if (fault != 0) return std::nullopt;  // the count and fill passes disagreed
  out.words = std::make_unique<DeviceBuffer>(out.count * 3 * sizeof(uint32_t));
  out.tail = std::move(tails);
  {
    const DeviceTimer::Pass timed(timer, "camera_pack");
    pack.use();
    glUniform1ui(pack.loc("uPixels"), GLuint(pixels));
    out.first->bind(0);
    out.words->bind(1);
    keepAt.bind(2);
    staging.bind(3);
    dispatch(pixels, 256);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
  }
  checkGl("the camera's fragments on the device");
  return out;
}

}  // namespace hairgen
