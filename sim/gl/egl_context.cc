// EGL headless context: Mesa's surfaceless platform (or a device platform on a
// vendor driver), or, for the GPU path, the device platform on the first EGL
// device that is not Mesa's software one; OpenGL core profile, no window system.

#include <EGL/egl.h>
#include <EGL/eglext.h>

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

class EglHeadlessContext final : public GlContext {
 public:
  explicit EglHeadlessContext(bool hardware_only) : hardware_only_(hardware_only) {
    auto get_platform_display = reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(
        eglGetProcAddress("eglGetPlatformDisplayEXT"));
    if (get_platform_display == nullptr) {
      throw RuntimeError("eglGetPlatformDisplayEXT is missing (no EGL_EXT_platform_base)");
    }
    EGLint major = 0, minor = 0;
    // Mesa's surfaceless platform first, unless a GPU is asked for; then
    // the device platform on the first (hardware) EGL device.
    if (!hardware_only) {
      display_ = get_platform_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
      if (display_ != EGL_NO_DISPLAY && !eglInitialize(display_, &major, &minor)) display_ = EGL_NO_DISPLAY;
    }
    if (display_ == EGL_NO_DISPLAY) {
      std::string seen;
      EGLDeviceEXT device = FirstDevice(hardware_only, &seen);
      if (device == nullptr && hardware_only) throw RuntimeError("no GPU among the EGL devices (" + seen + ")");
      if (device != nullptr) display_ = get_platform_display(EGL_PLATFORM_DEVICE_EXT, device, nullptr);
      if (display_ == EGL_NO_DISPLAY || !eglInitialize(display_, &major, &minor)) {
        throw RuntimeError(std::string(hardware_only ? "eglInitialize on the GPU's EGL device failed: "
                                                     : "eglInitialize failed: ") +
                           EglErrorString(eglGetError()));
      }
    }
    const EGLint config_attribs[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_SURFACE_TYPE,
                                     EGL_PBUFFER_BIT, EGL_NONE};
    EGLConfig config = nullptr;
    EGLint num_configs = 0;
    if (!eglChooseConfig(display_, config_attribs, &config, 1, &num_configs) || num_configs == 0) {
      // Surfaceless displays may offer configs without pbuffer support.
      const EGLint any_attribs[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_NONE};
      if (!eglChooseConfig(display_, any_attribs, &config, 1, &num_configs) || num_configs == 0) {
        eglTerminate(display_);
        throw RuntimeError("no EGL config with OpenGL");
      }
    }
    if (!eglBindAPI(EGL_OPENGL_API)) {
      eglTerminate(display_);
      throw RuntimeError("eglBindAPI(EGL_OPENGL_API) failed");
    }
    for (auto [maj, min] : {std::pair{4, 5}, std::pair{3, 3}}) {
      const EGLint context_attribs[] = {EGL_CONTEXT_MAJOR_VERSION, maj,
                                        EGL_CONTEXT_MINOR_VERSION, min,
                                        EGL_CONTEXT_OPENGL_PROFILE_MASK,
                                        EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
      context_ = eglCreateContext(display_, config, EGL_NO_CONTEXT, context_attribs);
      if (context_ != EGL_NO_CONTEXT) break;
    }
    if (context_ == EGL_NO_CONTEXT) {
      const EGLint error = eglGetError();
      eglTerminate(display_);
      throw RuntimeError("eglCreateContext (core 3.3+) failed: " + EglErrorString(error));
    }
    if (!eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, context_)) {
      const EGLint error = eglGetError();
      eglDestroyContext(display_, context_);
      eglTerminate(display_);
      throw RuntimeError("eglMakeCurrent (surfaceless) failed: " + EglErrorString(error));
    }
    gl_.Load([](const char* name) { return reinterpret_cast<void*>(eglGetProcAddress(name)); });
  }

  ~EglHeadlessContext() override {
    eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    eglDestroyContext(display_, context_);
    eglTerminate(display_);
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
