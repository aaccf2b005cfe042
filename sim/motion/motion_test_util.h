#pragma once
// Helpers shared by the motion library's tests.

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "sim/body/avatar.h"

namespace irbench::testing {

// A shipped avatar by name (avatars/NAME.json).
inline Avatar Person(const std::string& name) {
  return LoadAvatar(std::filesystem::path(IRBENCH_SOURCE_DIR) / "avatars" / (name + ".json"));
}

// `text` with the first `from` replaced by `to`; a `from` that is not there
// fails the test (the edit it was meant to make did not happen).
inline std::string Replace(std::string text, const std::string& from, const std::string& to) {
  const size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

}  // namespace irbench::testing
