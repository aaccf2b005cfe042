#pragma once
// NumPy's .npy format, version 1.0 (numpy.lib.format): a magic string, a
// Python-literal header with the dtype and shape, the raw little-endian data.
// What `numpy.load` and OpenCV users open directly.

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace irbench {

// The header (magic, version, length, dictionary padded to a multiple of 64
// bytes) of a C-order little-endian float32 array of `shape`.
std::string NpyFloat32Header(const std::vector<int64_t>& shape);

// Writes a rows x cols float32 array row by row; the file is complete when
// Close() has written the last row. Throws std::runtime_error on an I/O
// error or a row of another length; Close() throws when rows are missing.
class NpyRowWriter {
 public:
  NpyRowWriter(const std::filesystem::path& path, int64_t rows, int64_t cols);
  void Append(const std::vector<float>& row);
  void Close();

 private:
  std::filesystem::path path_;
  std::ofstream out_;
  int64_t rows_, cols_, written_ = 0;
};

// Reads a float32 .npy written as above: its shape and data. Throws
// std::runtime_error naming the file on anything else.
std::vector<float> ReadNpyFloat32(const std::filesystem::path& path, std::vector<int64_t>* shape);

}  // namespace irbench
