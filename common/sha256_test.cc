#include "common/sha256.h"

#include <gtest/gtest.h>

#include <unistd.h>

#include <fstream>

#include "common/error.h"

namespace irbench {
namespace {

// FIPS 180-2's examples.
TEST(Sha256Test, KnownDigests) {
  EXPECT_EQ(Sha256OfBytes(""), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  EXPECT_EQ(Sha256OfBytes("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  EXPECT_EQ(Sha256OfBytes("abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq"),
            "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
  const auto file = std::filesystem::temp_directory_path() / ("irbench_sha256_" + std::to_string(::getpid()));
  std::ofstream(file) << "abc";
  EXPECT_EQ(Sha256OfFile(file), Sha256OfBytes("abc"));
  std::filesystem::remove(file);
  EXPECT_THROW(Sha256OfFile(file), InputError);
}

}  // namespace
}  // namespace irbench
