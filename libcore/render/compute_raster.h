// hairgen's hair rasteriser (hair_raster.h) as GLSL compute passes: the light's maps (light_maps.h) and
// the camera's kept fragments (camera_fragments.h) drawn on the device with the same integer
// arithmetic as the CPU's, so a GPU gives the CPU's bits (tests/test_compute_raster.cpp compares the
// two on llvmpipe). The projection stays on the CPU (project(), in double precision as the CPU's
// rasteriser has it); everything after it runs on the device:
//   light:  the nearest depth per texel (an integer minimum), then each layer's coverage (integer sums,
//           a word that passes 2^32 flagged and read as the largest, as the CPU's sums saturate);
//   camera: each pixel's fragments counted, listed (offsets from a prefix sum), sorted by segment and
//           kept as the CPU keeps them, then packed as CameraFragments lays them out.
// Integer minima and sums, and a sort, do not depend on the order the device runs things in.
// Needs a current OpenGL 4.5 context with GL_ARB_gpu_shader_int64 (computeRasterAvailable).
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include <glm/glm.hpp>

#include "libcore/render/camera_fragments.h"
#include "libcore/render/gl_resources.h"
#include "libcore/render/hair_raster.h"
#include "libcore/render/light_maps.h"

namespace hairgen {

// Whether the current context can run the compute passes (GL_ARB_gpu_shader_int64).
bool computeRasterAvailable();

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
  template <class T>
  std::vector<T> read(size_t count) const;

  GLuint id = 0;
  size_t bytes = 0;
};

// Whether every segment of the projection is drawn within a software rasteriser's loop budget: llvmpipe
// ends a shader invocation's loops after 65,535 iterations in all (compute_raster.cpp), so there the
// passes take only projections within it, and the keeping pass pixels of a few hundred fragments at most
// (deeper, computeCameraFragments gives nothing and the CPU draws them).
bool withinLoopBudget(const raster::Projection& p);

// A projection (hair_raster.h: project()) uploaded: its points and segments. Each must fit a storage
// buffer (fitsDevice: 16 bytes a point, 4 a segment).
struct DeviceProjection {
  explicit DeviceProjection(const raster::Projection& p);
  raster::Projection read() const;  // back from the device, for the CPU's rasteriser
  int width, height;
  size_t segments;
  DeviceBuffer vertices, segmentList;
};

// The light's maps on the device: where the hair begins into `start` (R32F, metres; `background`
// where no hair reached) and each layer's opacity into `opacity` (RGBA32F, coverage × `strandOpacity`),
// both the projection's size. With `integers`, the integer maps are read back into it too (the test's
// comparison with rasteriseLightMaps).
void computeLightMaps(const DeviceProjection& hair, const glm::dvec4& layerSizes, double strandOpacity,
                      float background, const Texture& start, const Texture& opacity,
                      HairLightMaps* integers = nullptr);

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
// ones (12 bytes each) do not fit the device's buffers: the caller draws them on the CPU.
std::optional<DeviceFragments> computeCameraFragments(const DeviceProjection& hair, int kept,
                                                      const Texture* opaque, size_t slabBytes = 0);

}  // namespace hairgen
