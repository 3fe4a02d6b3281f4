// Reading rendered images back into an Image's planes: OpenGL reads them into a pixel-pack buffer (a
// GPU writes host memory at bus speed, with no pageable copy through the driver), every read queued
// before the buffer is mapped once, then its rows are copied, top to bottom, into the planes on TBB's
// threads. The same floats as reading the whole texture and splitting it.
#pragma once

#include <vector>

#include "libcore/render/gl_resources.h"

namespace hairgen {

// One channel of a single-level texture (R32F, RGBA16F, RGBA32F, ...) into a plane of
// width × height floats, rows top to bottom (OpenGL's rows go bottom to top).
struct PlaneRead {
  const Texture* texture = nullptr;
  int channel = 0;                      // 0-3: R, G, B, A
  std::vector<float>* plane = nullptr;  // resized to the texture's texels
};

// How the texels reach the buffer: each channel read on its own (the device de-interleaves; the copy
// is a memcpy a row), or each texture read once, whole, and its channels gathered on TBB's threads.
// kAuto: channels on a GPU; whole textures on a software rasteriser (llvmpipe converts a
// one-channel read texel by texel on one thread, and copies a whole one). The same floats either way.
enum class ReadbackLayout { kAuto, kChannels, kWholeTextures };

// Reads every plane of `reads` with the current context: all queued before the first is waited for.
// The pixel-pack buffer is kept by the current GlContext (GlContext::kept) for the next frame's
// readback. Throws Error (renderFailure) when OpenGL reports an error or the buffer cannot be mapped.
void readPlanes(const std::vector<PlaneRead>& reads, ReadbackLayout layout = ReadbackLayout::kAuto);

}  // namespace hairgen
