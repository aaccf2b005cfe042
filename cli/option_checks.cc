#include "cli/option_checks.h"

#include <charconv>
#include <limits>

#include "common/error.h"

namespace irbench::cli {
namespace {

// Parses `text` as a decimal integer of type T without sign prefix '+' or base
// prefix; on success rewrites it in canonical form and returns "", else why not.
template <typename T>
std::string ParseDecimal(std::string& text, T min, T max) {
  T value{};
  const char* first = text.data();
  const char* last = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(first, last, value);
  const std::string range = std::to_string(min) + ".." + std::to_string(max);
  if (text.empty() || ptr != last || (ec != std::errc() && ec != std::errc::result_out_of_range)) {
    return "'" + text + "' is not a whole number in " + range;
  }
  if (ec == std::errc::result_out_of_range || value < min || value > max) {
    return "'" + text + "' must be in " + range;
  }
  text = std::to_string(value);
  return "";
}

}  // namespace

CLI::Validator IntegerIn(long long min, long long max) {
  return CLI::Validator(
      [min, max](std::string& text) {
        if (min >= 0 && !text.empty() && text[0] == '-') {
          return "'" + text + "' must be in " + std::to_string(min) + ".." + std::to_string(max);
        }
        return ParseDecimal<long long>(text, min, max);
      },
      "INT in " + std::to_string(min) + ".." + std::to_string(max));
}

CLI::Validator Uint64Text() {
  return CLI::Validator(
      [](std::string& text) {
        if (!text.empty() && text[0] == '-') return "'" + text + "' must be in 0.." + std::to_string(UINT64_MAX);
        return ParseDecimal<uint64_t>(text, 0, std::numeric_limits<uint64_t>::max());
      },
      "UINT64");
}

void RequireNotEmpty(const CLI::App& cmd, const std::string& option, const std::string& value) {
  if (cmd.count(option) > 0 && value.empty()) {
    throw InputError("", option, "is empty; give a path (or leave the option out for the default)");
  }
}

}  // namespace irbench::cli
