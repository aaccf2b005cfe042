#pragma once
// Reading a whole file.

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

namespace irbench {

// A file's whole contents, byte for byte; empty when it cannot be opened (a
// caller that must tell the two apart checks that the file exists first).
inline std::string ReadFileBytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

}  // namespace irbench
