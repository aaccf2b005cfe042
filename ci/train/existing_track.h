#pragma once
// A sequence's own track, for training to reuse instead of tracking it again:
// the `track/` folder `irbench track SEQ` writes, when it holds a pose-stage
// track of all the sequence's frames. Gesture and motion-label training both
// learn from what the tracker made of a sequence (its errors included), and
// tracking a session costs more than training on it.

#include <filesystem>
#include <optional>
#include <vector>

#include <nlohmann/json.hpp>

namespace irbench {

struct ExistingTrack {
  nlohmann::json meta;               // track/track.json
  std::vector<nlohmann::json> lines;  // track.jsonl by frame; null where a frame has no line
};

// dir/track when its track.json says stage "pose" and `frames` frames, else
// nullopt (also for an unreadable track.json: the caller tracks instead).
std::optional<ExistingTrack> ReadExistingTrack(const std::filesystem::path& dir, int frames);

// The sha256 track.json records for one of the models the track was made
// with (models.<name>.sha256), or "" when it records none.
std::string TrackModelSha256(const ExistingTrack& track, const std::string& name);

}  // namespace irbench
