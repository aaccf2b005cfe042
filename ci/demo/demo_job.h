#pragma once
// `irbench demo`, the main job: render the default session (theater4, one
// person, about 20 s: entering, pointing at the helicopter, gestures, rest,
// leaving; the thesis sensor preset), run the tracker on it, score the track
// against the truth and print the tables.

#include <filesystem>
#include <optional>
#include <string>

namespace irbench {

struct DemoOptions {
  std::filesystem::path out;  // the sequence folder (default: <data root>/renders/demo); track/, score/ inside
  std::string avatar = "p1";
  std::string motion = "demo";
  std::string sensor = "thesis";
  std::optional<int> frames;  // default: the whole session
  uint64_t seed = 1;
  bool overwrite = false;
};

struct DemoResult {
  std::filesystem::path sequence, track, score;
  std::string tables;  // Markdown
};

DemoResult RunDemo(const DemoOptions& options);

}  // namespace irbench
