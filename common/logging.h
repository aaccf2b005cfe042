#pragma once
// The one logger: spdlog to stderr. Library code logs here, never to stdout.

#include <spdlog/spdlog.h>

namespace irbench {

spdlog::logger& Log();
// 0 quiet (warnings and errors), 1 info (default), 2 debug.
void SetVerbosity(int level);

}  // namespace irbench
