// A headless OpenGL 4.5 core context through EGL (no window system): the EGL device platform first
// (a GPU, e.g. NVIDIA's), then Mesa's surfaceless platform (llvmpipe on machines without a GPU).
// Rendering goes into framebuffer objects only.
#pragma once

#include <memory>
#include <string>
#include <vector>

namespace hairgen {

struct GlDeviceInfo {
  std::string platform;  // "device" or "surfaceless"
  std::string name;      // the EGL device's extensions or the renderer string
  bool opened = false;
  std::string error;  // why it did not open, EGL's error spelled out
};

class GlContext {
 public:
  // Opens the first platform that gives a 4.5 core context; throws DeviceError (exit 3) naming what
  // each platform answered when none does.
  GlContext();
  ~GlContext();
  GlContext(const GlContext&) = delete;
  GlContext& operator=(const GlContext&) = delete;

  const std::string& platform() const;  // "device" or "surfaceless"
  std::string renderer() const;         // GL_RENDERER, e.g. "llvmpipe (LLVM 15.0.6, 256 bits)"
  std::string version() const;          // GL_VERSION
  int maxTextureSize() const;           // GL_MAX_TEXTURE_SIZE, texels per side

  // Every EGL device and the surfaceless platform, each tried, for `hairgen render --list-devices`.
  static std::vector<GlDeviceInfo> probe();

 private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace hairgen
