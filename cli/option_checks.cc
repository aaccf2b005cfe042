#include "cli/option_checks.h"

#include <charconv>
#include <cmath>
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

// "FROM:TO" in seconds, FROM >= 0 and TO > FROM.
std::pair<double, double> ParseEmptyStage(const std::string& text) {
  const size_t colon = text.find(':');
  double from = 0, to = 0;
  try {
    if (colon == std::string::npos) throw std::invalid_argument("no colon");
    size_t used = 0;
    from = std::stod(text.substr(0, colon), &used);
    if (used != colon) throw std::invalid_argument("trailing text");
    to = std::stod(text.substr(colon + 1), &used);
    if (used != text.size() - colon - 1) throw std::invalid_argument("trailing text");
  } catch (const std::exception&) {
    throw InputError("", "--empty-stage", "expected FROM:TO in seconds (e.g. 0:2), got '" + text + "'");
  }
  if (!(std::isfinite(from) && std::isfinite(to) && from >= 0 && to > from)) {
    throw InputError("", "--empty-stage", "needs 0 <= FROM < TO, got '" + text + "'");
  }
  return {from, to};
}

}  // namespace irbench::cli
