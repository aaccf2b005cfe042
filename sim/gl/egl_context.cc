// EGL headless context: Mesa's surfaceless platform (or a device platform on a
// vendor driver), or, for the GPU path, the device platform on the first EGL
// device that is not Mesa's software one; OpenGL core profile, no window system.

#include <EGL/egl.h>
#include <EGL/eglext.h>

#include <mutex>
#include <string>

#include "common/error.h"
#include "sim/gl/gl_context.h"

namespace irbench {
namespace {

std::string EglErrorString(EGLint error) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "0x%04x", static_cast<unsigned>(error));
  return buffer;
}

// The first EGL device, or with `hardware_only` the first that is not Mesa's
// software renderer; null when there is none, with what was found in `seen`.
EGLDeviceEXT FirstDevice(bool hardware_only, std::string* seen) {
  auto query_devices = reinterpret_cast<PFNEGLQUERYDEVICESEXTPROC>(eglGetProcAddress("eglQueryDevicesEXT"));
  auto query_string =
      reinterpret_cast<PFNEGLQUERYDEVICESTRINGEXTPROC>(eglGetProcAddress("eglQueryDeviceStringEXT"));
  if (query_devices == nullptr || (hardware_only && query_string == nullptr)) {
    *seen = "no EGL_EXT_device_enumeration";
    return nullptr;
  }
  EGLDeviceEXT devices[16];
  EGLint count = 0;
  if (!query_devices(16, devices, &count)) count = 0;
  *seen = std::to_string(count) + " EGL device(s)";
  for (EGLint i = 0; i < count; ++i) {
    if (!hardware_only) return devices[i];
    const char* extensions = query_string(devices[i], EGL_EXTENSIONS);
    const std::string ext = extensions != nullptr ? extensions : "";
    if (ext.find("EGL_MESA_device_software") == std::string::npos) return devices[i];
  }
  if (hardware_only) *seen += ", all software";
  return nullptr;
}

// The process's EGL display of each kind (Mesa's surfaceless one or a GPU's
// device), initialised on first use and never terminated: every context of the
// process, on whichever thread, is made on it. eglTerminate is not counted
// (one call ends the display for every thread) and unloads the driver, whose
// per-thread state other threads may still hold: the likely cause of a
// sweep's one crash (a render ending on one thread while the next began on
// another). Keeping it also spares each later render the driver's start-up.
EGLDisplay InitialisedDisplay(bool hardware_only) {
  static std::mutex mutex;
  static EGLDisplay displays[2] = {EGL_NO_DISPLAY, EGL_NO_DISPLAY};
  const std::lock_guard<std::mutex> lock(mutex);
  EGLDisplay& display = displays[hardware_only ? 1 : 0];
  if (display != EGL_NO_DISPLAY) return display;
  auto get_platform_display =
      reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(eglGetProcAddress("eglGetPlatformDisplayEXT"));
  if (get_platform_display == nullptr) {
    throw RuntimeError("eglGetPlatformDisplayEXT is missing (no EGL_EXT_platform_base)");
  }
  EGLint major = 0, minor = 0;
  // Mesa's surfaceless platform first, unless a GPU is asked for; then the
  // device platform on the first (hardware) EGL device.
  EGLDisplay found = EGL_NO_DISPLAY;
  if (!hardware_only) {
    found = get_platform_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
    if (found != EGL_NO_DISPLAY && !eglInitialize(found, &major, &minor)) found = EGL_NO_DISPLAY;
  }
  if (found == EGL_NO_DISPLAY) {
    std::string seen;
    EGLDeviceEXT device = FirstDevice(hardware_only, &seen);
    if (device == nullptr && hardware_only) throw RuntimeError("no GPU among the EGL devices (" + seen + ")");
    if (device != nullptr) found = get_platform_display(EGL_PLATFORM_DEVICE_EXT, device, nullptr);
    if (found == EGL_NO_DISPLAY || !eglInitialize(found, &major, &minor)) {
      throw RuntimeError(std::string(hardware_only ? "eglInitialize on the GPU's EGL device failed: "
                                                   : "eglInitialize failed: ") +
                         EglErrorString(eglGetError()));
    }
  }
  display = found;
  return display;
}

class EglHeadlessContext final : public GlContext {
 public:
  explicit EglHeadlessContext(bool hardware_only)
      : hardware_only_(hardware_only), display_(InitialisedDisplay(hardware_only)) {
    const EGLint config_attribs[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_SURFACE_TYPE,
                                     EGL_PBUFFER_BIT, EGL_NONE};
    EGLConfig config = nullptr;
    EGLint num_configs = 0;
    if (!eglChooseConfig(display_, config_attribs, &config, 1, &num_configs) || num_configs == 0) {
      // Surfaceless displays may offer configs without pbuffer support.
      const EGLint any_attribs[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_NONE};
      if (!eglChooseConfig(display_, any_attribs, &config, 1, &num_configs) || num_configs == 0) {
        throw RuntimeError("no EGL config with OpenGL");
      }
    }
    if (!eglBindAPI(EGL_OPENGL_API)) throw RuntimeError("eglBindAPI(EGL_OPENGL_API) failed");
    for (auto [maj, min] : {std::pair{4, 5}, std::pair{3, 3}}) {
      const EGLint context_attribs[] = {EGL_CONTEXT_MAJOR_VERSION, maj,
                                        EGL_CONTEXT_MINOR_VERSION, min,
                                        EGL_CONTEXT_OPENGL_PROFILE_MASK,
                                        EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
      context_ = eglCreateContext(display_, config, EGL_NO_CONTEXT, context_attribs);
      if (context_ != EGL_NO_CONTEXT) break;
    }
    if (context_ == EGL_NO_CONTEXT) {
      throw RuntimeError("eglCreateContext (core 3.3+) failed: " + EglErrorString(eglGetError()));
    }
    if (!eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, context_)) {
      const EGLint error = eglGetError();
      eglDestroyContext(display_, context_);
      throw RuntimeError("eglMakeCurrent (surfaceless) failed: " + EglErrorString(error));
    }
    gl_.Load([](const char* name) { return reinterpret_cast<void*>(eglGetProcAddress(name)); });
  }

  // The context goes with this thread's EGL state; the display stays.
  ~EglHeadlessContext() override {
    eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    eglDestroyContext(display_, context_);
    eglReleaseThread();
  }

  std::string BackendName() const override { return hardware_only_ ? "gpu" : "egl"; }

 private:
  bool hardware_only_ = false;
  EGLDisplay display_ = EGL_NO_DISPLAY;
  EGLContext context_ = EGL_NO_CONTEXT;
};

}  // namespace

std::unique_ptr<GlContext> CreateEglHeadlessContext(bool hardware_only) {
  return std::make_unique<EglHeadlessContext>(hardware_only);
}

}  // namespace irbench
