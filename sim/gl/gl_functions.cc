#include "sim/gl/gl_functions.h"

#include "common/error.h"

namespace irbench {

void GlFunctions::Load(const std::function<void*(const char*)>& get_proc) {
#define IRBENCH_GL_LOAD(type, name)                                           \
  name = reinterpret_cast<type>(get_proc("gl" #name));                        \
  if (name == nullptr) throw RuntimeError("OpenGL function gl" #name " is not available");
  IRBENCH_GL_FUNCTIONS(IRBENCH_GL_LOAD)
#undef IRBENCH_GL_LOAD
}

}  // namespace irbench
