#include "common/atomic_file.h"

#include <gtest/gtest.h>

#include <fstream>

#include "common/error.h"

namespace irbench {
namespace fs = std::filesystem;
namespace {

fs::path FreshDir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("irbench_atomic_" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

TEST(AtomicFileTest, WritesAndLeavesNoTemporaries) {
  const fs::path dir = FreshDir("write");
  AtomicWriteFile(dir / "a.txt", "hello");
  std::ifstream in(dir / "a.txt");
  std::string text;
  in >> text;
  EXPECT_EQ(text, "hello");
  int files = 0;
  for (const auto& e : fs::directory_iterator(dir)) files += e.is_regular_file();
  EXPECT_EQ(files, 1);
}

TEST(AtomicFileTest, StagingDirVanishesUnlessCommitted) {
  const fs::path dir = FreshDir("staging");
  {
    StagingDir staging(dir / "out", false, "--out");
    AtomicWriteFile(staging.path() / "x", "1");
    EXPECT_FALSE(fs::exists(dir / "out"));
  }
  EXPECT_TRUE(fs::is_empty(dir));
  {
    StagingDir staging(dir / "out", false, "--out");
    AtomicWriteFile(staging.path() / "x", "1");
    staging.Commit();
  }
  EXPECT_TRUE(fs::exists(dir / "out" / "x"));
  EXPECT_THROW(StagingDir(dir / "out", false, "--out"), InputError);
  EXPECT_THROW(StagingDir(dir / "missing" / "out", false, "--out"), InputError);
  {
    StagingDir staging(dir / "out", true, "--out");
    AtomicWriteFile(staging.path() / "y", "2");
    staging.Commit();
  }
  EXPECT_TRUE(fs::exists(dir / "out" / "y"));
  EXPECT_FALSE(fs::exists(dir / "out" / "x"));
}

}  // namespace
}  // namespace irbench
