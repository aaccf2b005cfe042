#pragma once
// Headless OpenGL behind one interface. Backends:
//   egl    - EGL on Mesa's surfaceless platform (llvmpipe here; a vendor EGL
//            where a GPU exists), the primary path;
//   osmesa - Mesa's off-screen library, from its own module;
//   gpu    - EGL's device platform on the first device that is not Mesa's
//            software one (an NVIDIA, AMD or Intel GPU); an error without one;
//   auto   - egl, falling back to osmesa (llvmpipe, the reference pixels,
//            where Mesa is installed).
// Contexts are OpenGL 3.3 core (or newer); all rendering goes into FBOs.

#include <memory>
#include <optional>
#include <string>

#include "sim/gl/gl_functions.h"

namespace irbench {

enum class GlBackend { kAuto, kEgl, kOsMesa, kGpu };

// Parses "auto" | "egl" | "osmesa" | "gpu"; nullopt otherwise.
std::optional<GlBackend> ParseGlBackend(const std::string& name);
// "auto", "egl", "osmesa" or "gpu".
std::string GlBackendName(GlBackend backend);

class GlContext {
 public:
  virtual ~GlContext() = default;
  // "egl", "osmesa" or "gpu".
  virtual std::string BackendName() const = 0;
  const GlFunctions& gl() const { return gl_; }
  // GL_RENDERER and GL_VERSION strings.
  std::string RendererString() const;

 protected:
  GlFunctions gl_;
};


// Creates and makes current a context; throws RuntimeError with the reasons of
// every backend tried.
std::unique_ptr<GlContext> CreateGlContext(GlBackend backend);

}  // namespace irbench
