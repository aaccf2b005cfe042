#pragma once
// `irbench motion list | info | export`: the motion library and clips from the
// command line.

#include <cstdint>
#include <filesystem>
#include <string>

namespace irbench {

// The library motions and the files in motions/, one per line.
std::string MotionListText();

// A BVH or AMC clip's convention, frames, frame time, duration and joint map.
std::string MotionInfoText(const std::filesystem::path& file);

struct MotionExportOptions {
  std::string motion;
  std::string avatar = "p1";
  std::string scene = "theater";
  double fps = 30;
  uint64_t seed = 1;
  std::filesystem::path out;
  bool overwrite = false;
};

// Writes the motion as BVH on the avatar's skeleton; returns the file.
std::filesystem::path ExportMotion(const MotionExportOptions& options);

}  // namespace irbench
