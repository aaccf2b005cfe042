#include "sim/gl/gl_context.h"

#include "common/error.h"
#include "common/logging.h"

namespace irbench {

std::unique_ptr<GlContext> CreateEglHeadlessContext(bool hardware_only);  // egl_context.cc
std::unique_ptr<GlContext> CreateOsMesaContext();       // osmesa_context.cc

std::optional<GlBackend> ParseGlBackend(const std::string& name) {
  if (name == "auto") return GlBackend::kAuto;
  if (name == "egl") return GlBackend::kEgl;
  if (name == "osmesa") return GlBackend::kOsMesa;
  if (name == "gpu") return GlBackend::kGpu;
  return std::nullopt;
}

std::string GlBackendName(GlBackend backend) {
  switch (backend) {
    case GlBackend::kEgl:
      return "egl";
    case GlBackend::kOsMesa:
      return "osmesa";
    case GlBackend::kGpu:
      return "gpu";
    case GlBackend::kAuto:
      break;
  }
  return "auto";
}

std::string GlContext::RendererString() const {
  auto str = [&](GLenum e) {
    const GLubyte* s = gl_.GetString(e);
    return s != nullptr ? std::string(reinterpret_cast<const char*>(s)) : std::string("?");
  };
  return str(GL_RENDERER) + " | " + str(GL_VERSION);
}

std::unique_ptr<GlContext> CreateGlContext(GlBackend backend) {
  if (backend == GlBackend::kEgl) return CreateEglHeadlessContext(false);
  if (backend == GlBackend::kGpu) return CreateEglHeadlessContext(true);
  if (backend == GlBackend::kOsMesa) return CreateOsMesaContext();
  try {
    return CreateEglHeadlessContext(false);
  } catch (const RuntimeError& egl_error) {
    Log().warn("EGL unavailable ({}); falling back to OSMesa", egl_error.what());
    try {
      return CreateOsMesaContext();
    } catch (const RuntimeError& osmesa_error) {
      throw RuntimeError(std::string("no OpenGL backend works: egl: ") + egl_error.what() +
                         "; osmesa: " + osmesa_error.what());
    }
  }
}

}  // namespace irbench
