#pragma once
// What the closed-loop tests read back of a track: JSON-lines files and the
// tracked fraction and mean error of the nine scored upper-body joints
// against the truth (a quick stand-in for irbench score's tables).

#include <Eigen/Core>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace irbench::testing {

inline std::vector<nlohmann::json> ReadJsonLines(const std::filesystem::path& path) {
  std::vector<nlohmann::json> lines;
  std::ifstream in(path);
  for (std::string line; std::getline(in, line);) lines.push_back(nlohmann::json::parse(line));
  return lines;
}

inline Eigen::Vector3d JointVector(const nlohmann::json& j) {
  return {j[0].get<double>(), j[1].get<double>(), j[2].get<double>()};
}

// Tracked frames (of those with the person present) and the mean error (cm)
// of root, waist, neck, shoulders, elbows and wrists over them.
struct TrackFigures {
  int present = 0, tracked = 0;
  double mean_error_cm = 0;
  double Fraction() const { return present ? static_cast<double>(tracked) / present : 0; }
};

inline TrackFigures UpperBodyFigures(const std::vector<nlohmann::json>& track,
                                     const std::vector<nlohmann::json>& truth) {
  TrackFigures f;
  double sum = 0;
  int n = 0;
  for (size_t i = 0; i < track.size() && i < truth.size(); ++i) {
    const nlohmann::json& t = truth[i];
    if (!t["present"].get<bool>()) continue;
    ++f.present;
    if (track[i]["state"] != "tracking") continue;
    ++f.tracked;
    for (const char* j : {"root", "waist", "neck", "left_shoulder", "right_shoulder", "left_elbow", "right_elbow",
                          "left_wrist", "right_wrist"}) {
      sum += 100 * (JointVector(track[i]["joints3d"][j]) - JointVector(t["joints3d"][j])).norm();
      ++n;
    }
  }
  f.mean_error_cm = n ? sum / n : 0;
  return f;
}

}  // namespace irbench::testing
