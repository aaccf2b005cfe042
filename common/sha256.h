#pragma once
// SHA-256 of a file (OpenSSL's libcrypto), as 64 lower-case hex digits: how
// an output names the exact model files it used.

#include <filesystem>
#include <string>
#include <string_view>

namespace irbench {

// Throws InputError naming the file when it cannot be read.
std::string Sha256OfFile(const std::filesystem::path& file);
std::string Sha256OfBytes(std::string_view bytes);

}  // namespace irbench
