#pragma once
// Helpers shared by the closed-loop tests.

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace irbench::testing {

inline std::filesystem::path FreshTempDir(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / ("irbench_test_" + name);
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

inline void WriteText(const std::filesystem::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
}

inline std::string ReadText(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream buffer;
  buffer << in.rdbuf();
  return buffer.str();
}

// A short motion with wide arm and body movement, so a few frames cover
// raised, crossed and hidden arms.
inline std::string FastMotionJson() {
  return R"({"format": "irbench.keyframes/1", "name": "fast", "keys": [
    {"t": 0.0, "joints": {"right_shoulder": [0, 80, 0], "left_shoulder": [0, -80, 0]}},
    {"t": 0.1, "root": [0.2, 0.1, 0], "heading_deg": 40,
     "joints": {"right_shoulder": [0, -60, 20], "right_elbow": [0, -40, 0], "left_shoulder": [0, 10, -80],
                "left_elbow": [0, 0, -90], "right_hip": [20, 0, 0], "left_knee": [-30, 0, 0]}},
    {"t": 0.2, "root": [-0.3, -0.2, -0.15], "heading_deg": -60,
     "joints": {"right_shoulder": [0, 20, 100], "right_elbow": [0, 0, 60], "left_shoulder": [0, 60, 0],
                "spine": [15, 0, 0], "right_knee": [-40, 0, 0], "left_hip": [30, 0, 0]}}]})";
}

}  // namespace irbench::testing
