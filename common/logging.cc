#include "common/logging.h"

#include <spdlog/sinks/stdout_color_sinks.h>
#include <unistd.h>

namespace irbench {

spdlog::logger& Log() {
  static std::shared_ptr<spdlog::logger> logger = [] {
    auto l = spdlog::stderr_color_mt("irbench");
    // On a terminal each message first clears the line a progress display
    // (common/progress.h) may be rewriting.
    l->set_pattern(::isatty(STDERR_FILENO) == 1 ? "\r\033[K%^%l%$: %v" : "%^%l%$: %v");
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
