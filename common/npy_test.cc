#include "common/npy.h"

#include <gtest/gtest.h>

#include <filesystem>

namespace irbench {
namespace {

TEST(Npy, HeaderIsNumpysVersionOneLayout) {
  const std::string h = NpyFloat32Header({3, 13824});
  EXPECT_EQ(h.size() % 64, 0u);
  EXPECT_EQ(h.substr(0, 6), "\x93NUMPY");
  EXPECT_EQ(h[6], 1);
  EXPECT_EQ(h[7], 0);
  EXPECT_EQ(static_cast<size_t>(static_cast<unsigned char>(h[8]) | (static_cast<unsigned char>(h[9]) << 8)), h.size() - 10);
  EXPECT_NE(h.find("{'descr': '<f4', 'fortran_order': False, 'shape': (3, 13824), }"), std::string::npos);
  EXPECT_EQ(h.back(), '\n');
  EXPECT_NE(NpyFloat32Header({5}).find("'shape': (5,)"), std::string::npos);
}

TEST(Npy, RowsWrittenAreReadBack) {
  const auto path = std::filesystem::temp_directory_path() / "irbench_npy_test.npy";
  {
    NpyRowWriter w(path, 2, 3);
    w.Append({1.0f, 2.5f, -3.0f});
    EXPECT_THROW(w.Append({1.0f}), std::runtime_error);
    w.Append({0.0f, 1e-3f, 7.0f});
    w.Close();
  }
  std::vector<int64_t> shape;
  const std::vector<float> data = ReadNpyFloat32(path, &shape);
  EXPECT_EQ(shape, (std::vector<int64_t>{2, 3}));
  EXPECT_EQ(data, (std::vector<float>{1.0f, 2.5f, -3.0f, 0.0f, 1e-3f, 7.0f}));
  // Fewer rows than the header promised is an error at Close.
  NpyRowWriter short_writer(path, 2, 1);
  short_writer.Append({1.0f});
  EXPECT_THROW(short_writer.Close(), std::runtime_error);
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace irbench
