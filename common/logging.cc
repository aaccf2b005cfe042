#include "common/logging.h"

#include <spdlog/sinks/stdout_color_sinks.h>

namespace irbench {

spdlog::logger& Log() {
  static std::shared_ptr<spdlog::logger> logger = [] {
    auto l = spdlog::stderr_color_mt("irbench");
    l->set_pattern("%^%l%$: %v");
    l->set_level(spdlog::level::info);
    return l;
  }();
  return *logger;
}

void SetVerbosity(int level) {
  Log().set_level(level <= 0 ? spdlog::level::warn
                             : level == 1 ? spdlog::level::info : spdlog::level::debug);
}

}  // namespace irbench
