#include "sequence_format/frame_lines.h"

#include <fstream>
#include <string>

#include "common/error.h"

namespace irbench {
namespace fs = std::filesystem;
using Json = nlohmann::json;

std::vector<Json> ReadJsonLines(const fs::path& path, std::map<int, Json>* by_frame) {
  std::ifstream in(path);
  if (!in) throw InputError(path.string(), "", "cannot read (no such file?)");
  std::vector<Json> lines;
  std::string text;
  for (int line = 1; std::getline(in, text); ++line) {
    if (text.find_first_not_of(" \t\r") == std::string::npos) continue;
    Json j;
    try {
      j = Json::parse(text);
    } catch (const Json::parse_error& e) {
      throw InputError(path.string(), "line " + std::to_string(line), std::string("not JSON: ") + e.what());
    }
    if (!j.is_object() || !j.contains("frame") || !j["frame"].is_number_integer()) {
      throw InputError(path.string(), "line " + std::to_string(line) + ": frame", "missing or not an integer");
    }
    const int frame = j["frame"];
    if (by_frame->count(frame)) {
      throw InputError(path.string(), "line " + std::to_string(line) + ": frame",
                       "frame " + std::to_string(frame) + " appears twice");
    }
    j["_line"] = line;
    (*by_frame)[frame] = j;
    lines.push_back(j);
  }
  return lines;
}

std::map<int, Json> ReadFrameLines(const fs::path& path) {
  std::map<int, Json> by_frame;
  ReadJsonLines(path, &by_frame);
  return by_frame;
}

}  // namespace irbench
