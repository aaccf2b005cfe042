#pragma once
// Checking a rendered sequence's truth joints against its truth masks (needs
// OpenCV's imgproc and imgcodecs).

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>

#include "sequence_format/manifest.h"
#include "tests/test_util.h"

namespace irbench::testing {

// Largest distance (px) of a visible truth joint from the mask, over the
// sequence; counts the visible joints checked; names the worst (joint, camera,
// frame) when `worst_at` is given.
inline double WorstVisibleJointOffMask(const std::filesystem::path& seq, int* visible,
                                       std::string* worst_at = nullptr,
                                       std::map<std::string, double>* worst_per_joint = nullptr) {
  const auto manifest = ReadManifest(seq).json;
  std::ifstream truth(seq / "truth/frames.jsonl");
  std::string line;
  double worst = 0;
  while (std::getline(truth, line)) {
    const auto frame = nlohmann::json::parse(line);
    char file[32];
    std::snprintf(file, sizeof(file), "%06d.png", frame["frame"].get<int>());
    for (const auto& cam : manifest["cameras"]) {
      const cv::Mat mask = cv::imread((seq / "truth/masks" / cam.get<std::string>() / file).string(),
                                      cv::IMREAD_UNCHANGED);
      if (mask.empty()) return 1e9;
      cv::Mat distance;
      cv::distanceTransform(255 - mask, distance, cv::DIST_L2, cv::DIST_MASK_PRECISE);
      for (const auto& [joint, uvv] : frame["joints2d"][cam.get<std::string>()].items()) {
        if (uvv[2] != 2 || joint == "root") continue;
        const int u = int(std::lround(double(uvv[0]))), v = int(std::lround(double(uvv[1])));
        if (u < 0 || v < 0 || u >= mask.cols || v >= mask.rows) return 1e9;
        const double d = distance.at<float>(v, u);
        if (d > worst && worst_at) *worst_at = joint + " in " + cam.get<std::string>() + " " + file;
        worst = std::max(worst, d);
        if (worst_per_joint) (*worst_per_joint)[joint] = std::max((*worst_per_joint)[joint], d);
        ++*visible;
      }
    }
  }
  return worst;
}

}  // namespace irbench::testing
