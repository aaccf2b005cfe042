#include "common/sha256.h"

#include <openssl/evp.h>

#include <fstream>
#include <iterator>

#include "common/error.h"

namespace irbench {

std::string Sha256OfBytes(std::string_view bytes) {
  unsigned char digest[EVP_MAX_MD_SIZE];
  unsigned int length = 0;
  if (EVP_Digest(bytes.data(), bytes.size(), digest, &length, EVP_sha256(), nullptr) != 1) {
    throw RuntimeError("SHA-256 failed");
  }
  static const char kHex[] = "0123456789abcdef";
  std::string hex;
  for (unsigned int i = 0; i < length; ++i) {
    hex += kHex[digest[i] >> 4];
    hex += kHex[digest[i] & 15];
  }
  return hex;
}

std::string Sha256OfFile(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(file.string(), "file", "cannot be read");
  const std::string bytes(std::istreambuf_iterator<char>(in), {});
  return Sha256OfBytes(bytes);
}

}  // namespace irbench
