#pragma once
// For tests that score or report: a short session rendered quickly (lab4 rig
// in the theater, no empty-stage frames, no supersampling) and its truth.

#include <filesystem>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "sim/sequence/render_job.h"
#include "tests/shared_render.h"
#include "tests/test_util.h"

namespace irbench::testing {

// Writes `dir`/s.json (an irbench.session/1 with these `items`, 0.2 s
// crossfades), renders it to `dir`/seq (once per test binary and `items`:
// tests/shared_render.h) and returns the truth's lines.
inline std::vector<nlohmann::json> RenderSession(const std::filesystem::path& dir, const std::string& items) {
  WriteText(dir / "s.json", R"({"format": "irbench.session/1", "crossfade_s": 0.2, "items": )" + items + "}");
  RenderJobOptions options;
  options.rig = "lab4";
  options.scene = "theater";
  options.motion = (dir / "s.json").string();
  options.background_frames = 0;
  options.supersample = 1;
  options.out = dir / "seq";
  SharedRender("session-" + std::to_string(std::hash<std::string>{}(items)), options);
  std::vector<nlohmann::json> truth;
  std::ifstream in(dir / "seq/truth/frames.jsonl");
  for (std::string line; std::getline(in, line);) truth.push_back(nlohmann::json::parse(line));
  return truth;
}

}  // namespace irbench::testing
