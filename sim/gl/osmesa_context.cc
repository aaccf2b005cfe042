// OSMesa backend: loads libirbench_osmesa.so (beside the running program, or
// where the build put it, or $IRBENCH_OSMESA_MODULE) with dlopen and takes its
// GL functions from OSMesaGetProcAddress.

#include <dlfcn.h>
#include <unistd.h>

#include <filesystem>

#include "common/error.h"
#include "sim/gl/gl_context.h"

namespace irbench {
namespace {

using CreateFn = void* (*)(char* error, int error_len);
using GetProcFn = void* (*)(const char* name);
using DestroyFn = void (*)(void* handle);

std::vector<std::string> ModuleCandidates() {
  std::vector<std::string> candidates;
  if (const char* env = std::getenv("IRBENCH_OSMESA_MODULE"); env != nullptr && *env != '\0') {
    candidates.push_back(env);
  }
  std::error_code ec;
  const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    candidates.push_back((exe.parent_path() / "libirbench_osmesa.so").string());
    // Installed: <prefix>/bin/irbench and <prefix>/lib/irbench/.
    candidates.push_back((exe.parent_path() / ".." / "lib" / "irbench" / "libirbench_osmesa.so").string());
  }
  candidates.push_back(IRBENCH_OSMESA_MODULE_PATH);
  return candidates;
}

class OsMesaContext final : public GlContext {
 public:
  OsMesaContext() {
    std::string tried;
    for (const std::string& path : ModuleCandidates()) {
      module_ = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
      if (module_ != nullptr) break;
      tried += std::string(tried.empty() ? "" : "; ") + dlerror();
    }
    if (module_ == nullptr) throw RuntimeError("cannot load the OSMesa module: " + tried);
    auto create = reinterpret_cast<CreateFn>(dlsym(module_, "irbench_osmesa_create"));
    get_proc_ = reinterpret_cast<GetProcFn>(dlsym(module_, "irbench_osmesa_get_proc"));
    destroy_ = reinterpret_cast<DestroyFn>(dlsym(module_, "irbench_osmesa_destroy"));
    if (create == nullptr || get_proc_ == nullptr || destroy_ == nullptr) {
      dlclose(module_);
      throw RuntimeError("the OSMesa module lacks its entry points");
    }
    char error[256] = {0};
    handle_ = create(error, sizeof(error));
    if (handle_ == nullptr) {
      dlclose(module_);
      throw RuntimeError(std::string("OSMesa: ") + error);
    }
    GetProcFn get_proc = get_proc_;
    gl_.Load([get_proc](const char* name) { return get_proc(name); });
  }

  ~OsMesaContext() override {
    destroy_(handle_);
    // The module stays loaded: Mesa keeps per-process state that dlclose would orphan.
  }

  std::string BackendName() const override { return "osmesa"; }

 private:
  void* module_ = nullptr;
  void* handle_ = nullptr;
  GetProcFn get_proc_ = nullptr;
  DestroyFn destroy_ = nullptr;
};

}  // namespace

std::unique_ptr<GlContext> CreateOsMesaContext() { return std::make_unique<OsMesaContext>(); }

}  // namespace irbench
