// The OSMesa backend's module. It links libOSMesa and nothing else of GL, and
// exports three C functions; see osmesa_context.cc.

#include <GL/osmesa.h>

#include <cstdio>
#include <vector>

namespace {

struct Handle {
  OSMesaContext context = nullptr;
  std::vector<unsigned char> buffer;  // a tiny default framebuffer; we render to FBOs
};

}  // namespace

extern "C" __attribute__((visibility("default"))) void* irbench_osmesa_create(char* error,
                                                                              int error_len) {
  auto* handle = new Handle;
  for (int minor_version : {5, 3}) {
    const int major = minor_version == 5 ? 4 : 3;
    const int attribs[] = {OSMESA_FORMAT, OSMESA_RGBA, OSMESA_DEPTH_BITS, 24,
                           OSMESA_PROFILE, OSMESA_CORE_PROFILE, OSMESA_CONTEXT_MAJOR_VERSION, major,
                           OSMESA_CONTEXT_MINOR_VERSION, minor_version, 0};
    handle->context = OSMesaCreateContextAttribs(attribs, nullptr);
    if (handle->context != nullptr) break;
  }
  if (handle->context == nullptr) {
    std::snprintf(error, error_len, "OSMesaCreateContextAttribs (core 3.3+) failed");
    delete handle;
    return nullptr;
  }
  handle->buffer.resize(16 * 16 * 4);
  if (!OSMesaMakeCurrent(handle->context, handle->buffer.data(), GL_UNSIGNED_BYTE, 16, 16)) {
    std::snprintf(error, error_len, "OSMesaMakeCurrent failed");
    OSMesaDestroyContext(handle->context);
    delete handle;
    return nullptr;
  }
  return handle;
}

extern "C" __attribute__((visibility("default"))) void* irbench_osmesa_get_proc(const char* name) {
  return reinterpret_cast<void*>(OSMesaGetProcAddress(name));
}

extern "C" __attribute__((visibility("default"))) void irbench_osmesa_destroy(void* handle_ptr) {
  auto* handle = static_cast<Handle*>(handle_ptr);
  OSMesaDestroyContext(handle->context);
  delete handle;
}
