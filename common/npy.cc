#include "common/npy.h"

#include <bit>
#include <cstring>
#include <regex>
#include <sstream>
#include <stdexcept>

namespace irbench {
namespace {

constexpr char kMagic[] = "\x93NUMPY";
static_assert(std::endian::native == std::endian::little, "the .npy writer assumes a little-endian machine");

}  // namespace

std::string NpyFloat32Header(const std::vector<int64_t>& shape) {
  std::string dims;
  for (size_t i = 0; i < shape.size(); ++i) dims += (i ? ", " : "") + std::to_string(shape[i]);
  if (shape.size() == 1) dims += ",";
  std::string dict = "{'descr': '<f4', 'fortran_order': False, 'shape': (" + dims + "), }";
  // Magic (6) + version (2) + length (2) + dict + padding + '\n' = 64 k.
  const size_t unpadded = 10 + dict.size() + 1;
  dict += std::string((64 - unpadded % 64) % 64, ' ') + "\n";
  std::string header(kMagic, 6);
  header += '\x01';
  header += '\x00';
  const uint16_t length = static_cast<uint16_t>(dict.size());
  header += static_cast<char>(length & 0xff);
  header += static_cast<char>(length >> 8);
  return header + dict;
}

NpyRowWriter::NpyRowWriter(const std::filesystem::path& path, int64_t rows, int64_t cols)
    : path_(path), out_(path, std::ios::binary | std::ios::trunc), rows_(rows), cols_(cols) {
  if (!out_) throw std::runtime_error(path.string() + ": cannot write");
  const std::string header = NpyFloat32Header({rows, cols});
  out_.write(header.data(), static_cast<std::streamsize>(header.size()));
}

void NpyRowWriter::Append(const std::vector<float>& row) {
  if (static_cast<int64_t>(row.size()) != cols_ || written_ >= rows_) {
    throw std::runtime_error(path_.string() + ": a row of " + std::to_string(row.size()) + " values (expected " +
                             std::to_string(cols_) + ") or too many rows");
  }
  out_.write(reinterpret_cast<const char*>(row.data()), static_cast<std::streamsize>(row.size() * sizeof(float)));
  ++written_;
  if (!out_) throw std::runtime_error(path_.string() + ": write failed");
}

void NpyRowWriter::Close() {
  if (written_ != rows_) {
    throw std::runtime_error(path_.string() + ": " + std::to_string(written_) + " of " + std::to_string(rows_) +
                             " rows written");
  }
  out_.close();
  if (!out_) throw std::runtime_error(path_.string() + ": write failed");
}

std::vector<float> ReadNpyFloat32(const std::filesystem::path& path, std::vector<int64_t>* shape) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path.string() + ": cannot read");
  char head[10];
  in.read(head, 10);
  if (!in || std::memcmp(head, kMagic, 6) != 0 || head[6] != 1) {
    throw std::runtime_error(path.string() + ": not a version 1 .npy file");
  }
  const size_t length = static_cast<unsigned char>(head[8]) | (static_cast<unsigned char>(head[9]) << 8);
  std::string dict(length, '\0');
  in.read(dict.data(), static_cast<std::streamsize>(length));
  std::smatch m;
  if (!in || dict.find("'descr': '<f4'") == std::string::npos || dict.find("'fortran_order': False") == std::string::npos ||
      !std::regex_search(dict, m, std::regex(R"('shape': \(([0-9, ]*)\))"))) {
    throw std::runtime_error(path.string() + ": not a C-order float32 array");
  }
  shape->clear();
  std::stringstream dims(m[1].str());
  std::string item;
  int64_t count = 1;
  while (std::getline(dims, item, ',')) {
    if (item.find_first_not_of(' ') == std::string::npos) continue;
    shape->push_back(std::stoll(item));
    count *= shape->back();
  }
  std::vector<float> data(static_cast<size_t>(count));
  in.read(reinterpret_cast<char*>(data.data()), static_cast<std::streamsize>(data.size() * sizeof(float)));
  if (!in) throw std::runtime_error(path.string() + ": shorter than its shape");
  return data;
}

}  // namespace irbench
