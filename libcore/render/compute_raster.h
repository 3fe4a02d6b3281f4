// hairgen's hair rasteriser (hair_raster.h) as GLSL compute passes: the light's maps (light_maps.h) and
// the camera's kept fragments (camera_fragments.h) drawn on the device with the same integer
// arithmetic as the CPU's, so a GPU gives the CPU's bits (tests/test_compute_raster.cpp compares the
// two on llvmpipe). The projection stays on the CPU (project(), in double precision as the CPU's
// rasteriser has it); everything after it runs on the device:
//   light:  the nearest depth per texel (an integer minimum), then each layer's coverage (integer sums,
//           a word that passes 2^32 flagged and read as the largest, as the CPU's sums saturate);
//   camera: each pixel's fragments counted, listed (offsets from a prefix sum on the device), sorted by
//           segment and kept as the CPU keeps them, then packed as CameraFragments lays them out (their
//           places from another prefix sum); the host reads back only the rows' totals (to cut the
//           rows into slabs that fit) and the kept fragments' count.
// Integer minima and sums, and a sort, do not depend on the order the device runs things in.
// Needs a current OpenGL 4.5 context with GL_ARB_gpu_shader_int64 (computeRasterAvailable).
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "libcore/render/camera_fragments.h"
#include "libcore/render/device_timer.h"
#include "libcore/render/gl_resources.h"
#include "libcore/render/hair_raster.h"
#include "libcore/render/light_maps.h"

namespace hairgen {

// Whether the current context can run the compute passes (GL_ARB_gpu_shader_int64).
bool computeRasterAvailable();

// Why the current context's compiler cannot build every compute pass for `kept` fragments a pixel
// (renderFailure's words, the compiler's first error among them); empty when it builds them all. The
// programs are kept in the context for the passes, and the answer too. A driver whose compiler rejects
// a pass leaves a GPU drawing on the CPU, the same bits, rather than failing every render.
std::string computePassesFailure(int kept);

// Whether an array of `bytes` fits one of the device's storage buffers (GL_MAX_SHADER_STORAGE_BLOCK_SIZE:
// 128 MiB on llvmpipe, 2 GiB on NVIDIA's drivers).
bool fitsDevice(size_t bytes);

// A buffer on the device, `bytes` long (at least 4), uninitialised unless `data` is given.
struct DeviceBuffer {
  explicit DeviceBuffer(size_t bytes, const void* data = nullptr);
  ~DeviceBuffer();
  DeviceBuffer(const DeviceBuffer&) = delete;
  DeviceBuffer& operator=(const DeviceBuffer&) = delete;
  void clear(uint32_t word) const;  // every 32-bit word to `word`
  void bind(GLuint binding) const { glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding, id); }
  // `count` elements from element `first` (waits for the device's writes before).
  template <class T>
  std::vector<T> read(size_t count, size_t first = 0) const;

  GLuint id = 0;
  size_t bytes = 0;
};

// Whether every segment of the projection is drawn within a software rasteriser's loop budget: llvmpipe
// ends a shader invocation's loops after 65,535 iterations in all (compute_raster.cpp), so there the
// passes take only projections within it, and the keeping pass pixels of a few hundred fragments at most
// (deeper, computeCameraFragments gives nothing and the CPU draws them).
bool withinLoopBudget(const raster::Projection& p);

// Exclusive prefix sums on the device (glsl/prefix_sum.glsl, Blelloch's work-efficient scan): out[i] =
// Σ_{j<i} min(in[j], limit) for i ≤ count, so out[count] is the total. Sums are modulo 2^32 (exact where
// the true sum is below it): the same bits whatever order the device adds in. `in` holds at least
// `count` words, `out` count + 1 (count + 1 < 2^32). With `deepest`, its first word is raised to the
// largest in[j] (an atomic maximum: it must hold 0, or a lower bound, before). Making one compiles its
// programs (once per context: Program).
class PrefixSum {
 public:
  // The first pass's groups: kLanes invocations, each summing kPerInvocation words in turn, then the
  // lanes' totals scanned in shared memory. On llvmpipe, which switches between a group's invocations
  // at every barrier, long runs in turn and few lanes cost least (64 × 64: a 2-megapixel image's sums in
  // 0.02 s there, 0.09 s at 256 × 4); on a GPU a lane's 64 words lie in 2 cache lines of its own.
  static constexpr size_t kLanes = 64, kPerInvocation = 64, kBlock = kLanes * kPerInvocation;
  PrefixSum();
  void operator()(const DeviceBuffer& in, size_t count, const DeviceBuffer& out, uint32_t limit = UINT32_MAX,
                  const DeviceBuffer* deepest = nullptr) const;

 private:
  Program blocks_, add_;
};

// A projection (hair_raster.h: project()) uploaded: its points and segments. Each must fit a storage
// buffer (fitsDevice: 16 bytes a point, 4 a segment). With a timer, the upload is its transfer `upload`.
struct DeviceProjection {
  explicit DeviceProjection(const raster::Projection& p, DeviceTimer* timer = nullptr,
                            const char* upload = "projection_upload");
  // Back from the device, for the CPU's rasteriser; with a timer, its transfer camera_projection_read.
  raster::Projection read(DeviceTimer* timer = nullptr) const;
  int width, height;
  size_t segments;
  DeviceBuffer vertices, segmentList;
};

// The light's maps on the device: where the hair begins into `start` (R32F, metres; `background`
// where no hair reached) and each layer's opacity into `opacity` (RGBA32F, coverage × `strandOpacity`),
// both the projection's size. With `integers`, the integer maps are read back into it too (the test's
// comparison with rasteriseLightMaps). With a timer, its passes light_start, light_layers, light_finish.
void computeLightMaps(const DeviceProjection& hair, const glm::dvec4& layerSizes, double strandOpacity,
                      float background, const Texture& start, const Texture& opacity,
                      HairLightMaps* integers = nullptr, DeviceTimer* timer = nullptr);

// The camera's kept fragments on the device, laid out as CameraFragments': per pixel its first
// fragment (pixels + 1 words), three words a fragment, per pixel its tail.
struct DeviceFragments {
  size_t count = 0;
  std::unique_ptr<DeviceBuffer> first, words, tail;
  CameraFragments read(int width, int height) const;  // for tests
};

// cameraFragments() on the device. `opaque`: null, or a texture whose R channel is, per pixel, the depth
// along the camera's axis of what hides the hair behind it (the shading pass's data, after the head).
// The rows are drawn in slabs whose lists fit `slabBytes` (0: 1 GiB, or the device's largest storage
// buffer if smaller; 16 bytes a fragment). Nothing when the image's pixels, a row's fragments or the kept
// ones (12 bytes each) do not fit the device's buffers, or a pixel holds so many fragments that a row's
// could pass 2^32 (more than 2^32 / width): the caller draws them on the CPU. With a timer, its passes
// camera_count, camera_scan (the counts' prefix sums and the rows' totals), camera_fill and camera_keep
// (once a slab), camera_first (the kept counts' prefix sum) and camera_pack, and its transfers
// camera_totals_read and camera_kept_read.
std::optional<DeviceFragments> computeCameraFragments(const DeviceProjection& hair, int kept,
                                                      const Texture* opaque, size_t slabBytes = 0,
                                                      DeviceTimer* timer = nullptr);

}  // namespace hairgen
