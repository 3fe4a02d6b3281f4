#include "libcore/render/gl_context.h"

#include <cstdio>
#include <cstring>
#include <map>
#include <mutex>

#include <EGL/egl.h>
#include <EGL/eglext.h>
#define GL_GLEXT_PROTOTYPES 1
#include <GL/glcorearb.h>

#include "libcore/util/error.h"
#include "libcore/util/stopwatch.h"

namespace hairgen {
namespace {

const char* eglErrorName(EGLint e) {
  switch (e) {
    case EGL_SUCCESS:
      return "EGL_SUCCESS";
    case EGL_NOT_INITIALIZED:
      return "EGL_NOT_INITIALIZED";
    case EGL_BAD_ACCESS:
      return "EGL_BAD_ACCESS";
    case EGL_BAD_ALLOC:
      return "EGL_BAD_ALLOC";
    case EGL_BAD_ATTRIBUTE:
      return "EGL_BAD_ATTRIBUTE";
    case EGL_BAD_CONFIG:
      return "EGL_BAD_CONFIG";
    case EGL_BAD_CONTEXT:
      return "EGL_BAD_CONTEXT";
    case EGL_BAD_CURRENT_SURFACE:
      return "EGL_BAD_CURRENT_SURFACE";
    case EGL_BAD_DISPLAY:
      return "EGL_BAD_DISPLAY";
    case EGL_BAD_MATCH:
      return "EGL_BAD_MATCH";
    case EGL_BAD_NATIVE_PIXMAP:
      return "EGL_BAD_NATIVE_PIXMAP";
    case EGL_BAD_NATIVE_WINDOW:
      return "EGL_BAD_NATIVE_WINDOW";
    case EGL_BAD_PARAMETER:
      return "EGL_BAD_PARAMETER";
    case EGL_BAD_SURFACE:
      return "EGL_BAD_SURFACE";
    case EGL_CONTEXT_LOST:
      return "EGL_CONTEXT_LOST";
  }
  return "unknown EGL error";
}

std::string eglFailure(const char* call) {
  const EGLint error = eglGetError();
  char code[16];
  std::snprintf(code, sizeof code, "0x%04x", static_cast<unsigned>(error));
  return std::string(call) + " failed (" + eglErrorName(error) + ", " + code + ")";
}

// EGL gives every GlContext on a platform the same display, and eglTerminate ends it for all of them:
// the contexts open on each display, so only the last one to close terminates it.
std::mutex displaysMutex;
std::map<EGLDisplay, int> openOnDisplay;

void displayOpened(EGLDisplay display) {
  std::lock_guard<std::mutex> lock(displaysMutex);
  ++openOnDisplay[display];
}

void displayClosed(EGLDisplay display) {
  std::lock_guard<std::mutex> lock(displaysMutex);
  if (--openOnDisplay[display] > 0) return;
  openOnDisplay.erase(display);
  eglTerminate(display);
}

// Terminates a display no context is open on (what failed to open on it, or a probe, is given up).
void terminateUnused(EGLDisplay display) {
  std::lock_guard<std::mutex> lock(displaysMutex);
  if (openOnDisplay.count(display) == 0) eglTerminate(display);
}

// Initialises `display` and makes a 4.5 core context current on it without a surface; adds the time
// the display's initialisation took to `times->display` and the context's to `times->context`.
bool openOn(EGLDisplay display, EGLContext& context, std::string& error, GlStartTimes* times = nullptr) {
  Stopwatch clock;
  if (display == EGL_NO_DISPLAY) {
    error = eglFailure("eglGetPlatformDisplay");
    return false;
  }
  EGLint major = 0, minor = 0;
  const bool initialised = eglInitialize(display, &major, &minor);
  if (times) times->display += clock.lap();
  if (!initialised) {
    error = eglFailure("eglInitialize");
    return false;
  }
  const char* extensions = eglQueryString(display, EGL_EXTENSIONS);
  if (!extensions || !std::strstr(extensions, "EGL_KHR_surfaceless_context")) {
    error = "no EGL_KHR_surfaceless_context";
    terminateUnused(display);
    return false;
  }
  if (!eglBindAPI(EGL_OPENGL_API)) {
    error = eglFailure("eglBindAPI(EGL_OPENGL_API)");
    terminateUnused(display);
    return false;
  }
  const EGLint configAttribs[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_NONE};
  EGLConfig config = nullptr;
  EGLint count = 0;
  bool haveConfig = eglChooseConfig(display, configAttribs, &config, 1, &count) && count > 0;
  const EGLint contextAttribs[] = {EGL_CONTEXT_MAJOR_VERSION,
                                   4,
                                   EGL_CONTEXT_MINOR_VERSION,
                                   5,
                                   EGL_CONTEXT_OPENGL_PROFILE_MASK,
                                   EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
                                   EGL_NONE};
  context =
      eglCreateContext(display, haveConfig ? config : EGL_NO_CONFIG_KHR, EGL_NO_CONTEXT, contextAttribs);
  if (context == EGL_NO_CONTEXT) {
    error = eglFailure("eglCreateContext(OpenGL 4.5 core)");
    terminateUnused(display);
    return false;
  }
  if (!eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, context)) {
    error = eglFailure("eglMakeCurrent");
    eglDestroyContext(display, context);
    terminateUnused(display);
    return false;
  }
  if (times) times->context += clock.lap();
  return true;
}

struct Platforms {
  PFNEGLQUERYDEVICESEXTPROC queryDevices = nullptr;
  PFNEGLQUERYDEVICESTRINGEXTPROC queryDeviceString = nullptr;
  PFNEGLGETPLATFORMDISPLAYEXTPROC getPlatformDisplay = nullptr;
  Platforms() {
    queryDevices = reinterpret_cast<PFNEGLQUERYDEVICESEXTPROC>(eglGetProcAddress("eglQueryDevicesEXT"));
    queryDeviceString =
        reinterpret_cast<PFNEGLQUERYDEVICESTRINGEXTPROC>(eglGetProcAddress("eglQueryDeviceStringEXT"));
    getPlatformDisplay =
        reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(eglGetProcAddress("eglGetPlatformDisplayEXT"));
  }
  std::vector<EGLDeviceEXT> devices() const {
    std::vector<EGLDeviceEXT> list;
    EGLint n = 0;
    if (!queryDevices || !queryDevices(0, nullptr, &n) || n <= 0) return list;
    list.resize(static_cast<size_t>(n));
    if (!queryDevices(n, list.data(), &n)) list.clear();
    list.resize(static_cast<size_t>(std::max(n, 0)));
    return list;
  }
  std::string describe(EGLDeviceEXT device) const {
    const char* ext = queryDeviceString ? queryDeviceString(device, EGL_EXTENSIONS) : nullptr;
    return ext ? ext : "";
  }
};

// A device is a real GPU when it is not Mesa's software device.
bool isSoftware(const std::string& extensions) {
  return extensions.find("EGL_MESA_device_software") != std::string::npos;
}

}  // namespace

struct GlContext::State {
  EGLDisplay display = EGL_NO_DISPLAY;
  EGLContext context = EGL_NO_CONTEXT;
  std::string platform;
  GlStartTimes times;
};

namespace {

// The GlContext whose context is current on this thread (EGL's current context is per thread).
thread_local GlContext* currentContext = nullptr;

}  // namespace

GlContext::GlContext() : state_(std::make_unique<State>()) {
  Stopwatch clock;
  Platforms p;
  std::string tried;
  if (!p.getPlatformDisplay)
    throw DeviceError("EGL has no eglGetPlatformDisplayEXT; cannot open a headless display");
  const std::vector<EGLDeviceEXT> devices = p.devices();
  state_->times.devices = clock.lap();
  // 1. The EGL device platform: every device but Mesa's software one (that is the surfaceless path).
  for (EGLDeviceEXT device : devices) {
    std::string ext = p.describe(device);
    if (isSoftware(ext)) continue;
    std::string error;
    EGLDisplay display = p.getPlatformDisplay(EGL_PLATFORM_DEVICE_EXT, device, nullptr);
    if (openOn(display, state_->context, error, &state_->times)) {
      state_->display = display;
      state_->platform = "device";
      currentContext = this;
      displayOpened(display);
      return;
    }
    tried += (tried.empty() ? "" : "; ") + ("EGL device (" + ext + "): " + error);
  }
  // 2. Mesa's surfaceless platform.
  {
    std::string error;
    EGLDisplay display = p.getPlatformDisplay(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
    if (openOn(display, state_->context, error, &state_->times)) {
      state_->display = display;
      state_->platform = "surfaceless";
      currentContext = this;
      displayOpened(display);
      return;
    }
    tried += (tried.empty() ? "" : "; ") + ("Mesa surfaceless: " + error);
  }
  if (tried.empty()) tried = "no EGL device and no surfaceless platform";
  // One line, as every error is printed: what each platform answered, then what to install.
  throw DeviceError("no OpenGL 4.5 core context through EGL (" + tried +
                    "); install Mesa (libegl-mesa0 libgl1-mesa-dri) for software rendering, or a GPU "
                    "driver with EGL");
}

GlContext::~GlContext() {
  if (state_->display == EGL_NO_DISPLAY) return;
  // The kept objects are deleted in this context: current here while they go (a context opened in
  // the background may be current on no thread).
  if (!kept_.empty()) {
    makeCurrent();
    kept_.clear();
  }
  eglMakeCurrent(state_->display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
  eglDestroyContext(state_->display, state_->context);
  displayClosed(state_->display);
  if (currentContext == this) currentContext = nullptr;
}

void GlContext::makeCurrent() {
  if (!eglMakeCurrent(state_->display, EGL_NO_SURFACE, EGL_NO_SURFACE, state_->context))
    throw DeviceError(eglFailure("eglMakeCurrent"));
  currentContext = this;
}

void GlContext::release() {
  eglMakeCurrent(state_->display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
  if (currentContext == this) currentContext = nullptr;
}

GlContext* GlContext::current() {
  return currentContext;
}

std::future<std::unique_ptr<GlContext>> GlContext::openInBackground() {
  return std::async(std::launch::async, [] {
    auto gl = std::make_unique<GlContext>();
    gl->release();
    return gl;
  });
}

const GlStartTimes& GlContext::startTimes() const {
  return state_->times;
}

const std::string& GlContext::platform() const {
  return state_->platform;
}
std::string GlContext::renderer() const {
  return reinterpret_cast<const char*>(glGetString(GL_RENDERER));
}
std::string GlContext::version() const {
  return reinterpret_cast<const char*>(glGetString(GL_VERSION));
}

int GlContext::maxTextureSize() const {
  GLint size = 4096;
  glGetIntegerv(GL_MAX_TEXTURE_SIZE, &size);
  return size;
}

std::vector<GlDeviceInfo> GlContext::probe() {
  std::vector<GlDeviceInfo> out;
  Platforms p;
  if (!p.getPlatformDisplay) return out;
  auto tryOpen = [&](GlDeviceInfo info, EGLDisplay display) {
    EGLContext context = EGL_NO_CONTEXT;
    info.opened = openOn(display, context, info.error);
    if (info.opened) {
      info.name = std::string(reinterpret_cast<const char*>(glGetString(GL_RENDERER))) + ", OpenGL " +
                  reinterpret_cast<const char*>(glGetString(GL_VERSION));
      eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
      eglDestroyContext(display, context);
      terminateUnused(display);
    }
    out.push_back(info);
  };
  for (EGLDeviceEXT device : p.devices()) {
    std::string ext = p.describe(device);
    tryOpen({"device", ext, false, ""}, p.getPlatformDisplay(EGL_PLATFORM_DEVICE_EXT, device, nullptr));
  }
  tryOpen({"surfaceless", "", false, ""},
          p.getPlatformDisplay(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr));
  return out;
}

}  // namespace hairgen
