#include "common/error.h"

namespace irbench {
namespace {

std::string FormatInputError(const std::string& file,
                             const std::string& field,
                             const std::string& message) {
  std::string out;
  if (!file.empty()) out += file + ": ";
  if (!field.empty()) out += field + ": ";
  return out + message;
}

}  // namespace

InputError::InputError(std::string file, std::string field, const std::string& message)
    : std::runtime_error(FormatInputError(file, field, message)),
      file_(std::move(file)),
      field_(std::move(field)),
      message_(message) {}

}  // namespace irbench
