#include "sim/sequence/image_io.h"

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfOutputFile.h>

#include <opencv2/imgcodecs.hpp>

#include "common/atomic_file.h"
#include "common/error.h"

namespace irbench {

std::string EncodePng(const cv::Mat& image) {
  std::vector<uchar> bytes;
  if (!cv::imencode(".png", image, bytes, {cv::IMWRITE_PNG_COMPRESSION, 1})) {
    throw RuntimeError("PNG encoding failed");
  }
  return std::string(bytes.begin(), bytes.end());
}

void WritePngAtomic(const std::filesystem::path& path, const cv::Mat& image) {
  AtomicWriteFile(path, EncodePng(image));
}

void WriteDepthExrAtomic(const std::filesystem::path& path, const cv::Mat& depth) {
  CV_Assert(depth.type() == CV_32FC1 && depth.isContinuous());
  AtomicWriteWith(path, [&](const std::filesystem::path& tmp) {
    Imf::Header header(depth.cols, depth.rows);
    header.channels().insert("Z", Imf::Channel(Imf::FLOAT));
    header.compression() = Imf::ZIP_COMPRESSION;
    Imf::OutputFile file(tmp.c_str(), header);
    Imf::FrameBuffer frame_buffer;
    frame_buffer.insert("Z", Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(depth.data),
                                        sizeof(float), sizeof(float) * depth.cols));
    file.setFrameBuffer(frame_buffer);
    file.writePixels(depth.rows);
  });
}

}  // namespace irbench
