#pragma once
// A sequence's own track, for training to reuse instead of tracking it again:
// the `track/` folder `irbench track SEQ` writes, when it holds a pose-stage
// track of all the sequence's frames. Gesture and motion-label training both
// learn from what the tracker made of a sequence (its errors included), and
// tracking a session costs more than training on it.

#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace irbench {

struct ExistingTrack {
  nlohmann::json meta;               // track/track.json
  std::vector<nlohmann::json> lines;  // track.jsonl by frame; null where a frame has no line
};

// Why ReadExistingTrack gave nothing.
enum class ExistingTrackMiss { kNone, kOtherModels };

// dir/track when its track.json says stage "pose" and `frames` frames and
// records, for each of `models` (name -> sha256), that it was made with that
// model (models.<name>.sha256), else nullopt: also for an unreadable
// track.json, and the caller tracks instead. The models are compared before
// track.jsonl is read; `miss` says whether they were the reason.
std::optional<ExistingTrack> ReadExistingTrack(const std::filesystem::path& dir, int frames,
                                               const std::map<std::string, std::string>& models = {},
                                               ExistingTrackMiss* miss = nullptr);

}  // namespace irbench
