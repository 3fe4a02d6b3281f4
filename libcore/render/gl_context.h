// A headless OpenGL 4.5 core context through EGL (no window system): the EGL device platform first
// (a GPU, e.g. NVIDIA's), then Mesa's surfaceless platform (llvmpipe on machines without a GPU).
// Rendering goes into framebuffer objects only.
//
// One context serves a whole sequence (`render --frames`, `run` on a shot): what a frame makes that the
// next would make again (a program linked from the same GLSL, the readback's pixel-pack buffer) is
// kept in the context's store under a key naming everything it was made from, and handed back to the
// next frame that asks for the same key. A kept object is the one a fresh render would have made, so a
// frame of a sequence equals the frame rendered alone, byte for byte.
#pragma once

#include <future>
#include <map>
#include <memory>
#include <string>
#include <typeinfo>
#include <utility>
#include <vector>

namespace hairgen {

struct GlDeviceInfo {
  std::string platform;  // "device" or "surfaceless"
  std::string name;      // the EGL device's extensions or the renderer string
  bool opened = false;
  std::string error;  // why it did not open, EGL's error spelled out
};

// What opening a context cost (seconds): finding the EGL devices, initialising the display that
// opened (the driver's start), and creating the context and making it current.
struct GlStartTimes {
  double devices = 0.0, display = 0.0, context = 0.0;
};

class GlContext {
 public:
  // Opens the first platform that gives a 4.5 core context, current on the calling thread; throws
  // DeviceError (exit 3) naming what each platform answered when none does.
  GlContext();
  // Releases the context and the objects it keeps.
  ~GlContext();
  GlContext(const GlContext&) = delete;
  GlContext& operator=(const GlContext&) = delete;

  const std::string& platform() const;  // "device" or "surfaceless"
  std::string renderer() const;         // GL_RENDERER, e.g. "llvmpipe (LLVM 15.0.6, 256 bits)"
  std::string version() const;          // GL_VERSION
  int maxTextureSize() const;           // GL_MAX_TEXTURE_SIZE, texels per side
  const GlStartTimes& startTimes() const;

  // Makes the context current on the calling thread (it is current on the thread that opened it) and
  // this the thread's current() one; release() makes no context current there (before another
  // thread takes it).
  void makeCurrent();
  void release();
  // The GlContext current on this thread, or null: the one that opened or was last made current here.
  static GlContext* current();

  // Opens a context on another thread while the caller does other work (reading the hair), so the
  // driver's start overlaps it. get() on the future waits, and rethrows DeviceError when none opened;
  // the context it gives is current on no thread: call makeCurrent().
  static std::future<std::unique_ptr<GlContext>> openInBackground();

  // The object kept under `key` (for its type T), made by `make()` (a std::unique_ptr<T>) the first
  // time the key is asked for. `key` names everything the object is made from. What make() throws is
  // rethrown and nothing is kept. Needs the context current.
  template <class T, class Make>
  T& kept(const std::string& key, Make&& make) {
    const std::string full = std::string(typeid(T).name()) + '\n' + key;
    auto found = kept_.find(full);
    if (found != kept_.end()) return *static_cast<T*>(found->second.get());
    std::shared_ptr<T> made(make());
    T& object = *made;
    kept_.emplace(full, std::move(made));
    return object;
  }
  size_t keptCount() const { return kept_.size(); }

  // Every EGL device and the surfaceless platform, each tried, for `hairgen render --list-devices`.
  static std::vector<GlDeviceInfo> probe();

 private:
  struct State;
  std::unique_ptr<State> state_;
  // Declared last, so destroyed first: its GL objects go while the context is still there.
  std::map<std::string, std::shared_ptr<void>> kept_;
};

}  // namespace hairgen
