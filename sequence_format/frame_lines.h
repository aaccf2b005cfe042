#pragma once
// JSON-lines files keyed by frame (truth/frames.jsonl, track.jsonl): one
// reader for the harness (score, report) and the sim's dataset exports.

#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <vector>

namespace irbench {

// The lines of `path` in file order, each also put in `by_frame` under its
// `frame` with its line number as "_line". Blank lines are skipped. Throws
// InputError naming the file and line for a line that is not JSON, lacks an
// integer `frame`, or repeats one; and for a file that cannot be read.
std::vector<nlohmann::json> ReadJsonLines(const std::filesystem::path& path,
                                          std::map<int, nlohmann::json>* by_frame);

// A frames.jsonl or track.jsonl file by frame index (ReadJsonLines).
std::map<int, nlohmann::json> ReadFrameLines(const std::filesystem::path& path);

}  // namespace irbench
