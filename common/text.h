#pragma once
// Small text helpers shared across the libraries.

#include <string>

namespace irbench {

// `s` in lower case, ASCII letters only (names, keywords and file
// extensions; the locale plays no part).
inline std::string AsciiLower(std::string s) {
  for (char& c : s) {
    if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
  }
  return s;
}

}  // namespace irbench
