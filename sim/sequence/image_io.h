#pragma once
// Image files, written atomically (temporary name, then rename).

#include <filesystem>
#include <opencv2/core.hpp>
#include <string>

namespace irbench {

// 8- or 16-bit single-channel PNG.
void WritePngAtomic(const std::filesystem::path& path, const cv::Mat& image);
// Encodes without writing (for benchmarks).
std::string EncodePng(const cv::Mat& image);
// CV_32FC1 as a one-channel ("Z", 32-bit float) OpenEXR file.
void WriteDepthExrAtomic(const std::filesystem::path& path, const cv::Mat& depth);

}  // namespace irbench
