#include "ci/train/existing_track.h"

#include <fstream>

#include "sequence_format/frame_lines.h"

namespace irbench {

namespace fs = std::filesystem;

namespace {

// The sha256 track.json records for one of the models the track was made
// with (models.<name>.sha256), or "" when it records none.
std::string TrackModelSha256(const nlohmann::json& meta, const std::string& name) {
  const nlohmann::json& models = meta.contains("models") ? meta["models"] : nlohmann::json();
  if (!models.is_object() || !models.contains(name) || !models[name].is_object()) return "";
  const nlohmann::json& model = models[name];
  return model.contains("sha256") && model["sha256"].is_string() ? model["sha256"].get<std::string>() : "";
}

}  // namespace

std::optional<ExistingTrack> ReadExistingTrack(const fs::path& dir, int frames,
                                               const std::map<std::string, std::string>& models,
                                               ExistingTrackMiss* miss) {
  if (miss != nullptr) *miss = ExistingTrackMiss::kNone;
  const fs::path meta = dir / "track" / "track.json", lines = dir / "track" / "track.jsonl";
  if (!fs::exists(meta) || !fs::exists(lines)) return std::nullopt;
  ExistingTrack track;
  try {
    std::ifstream in(meta);
    track.meta = nlohmann::json::parse(in);
    if (!track.meta.is_object() || track.meta.value("stage", "") != "pose" || track.meta.value("frames", -1) != frames) {
      return std::nullopt;
    }
  } catch (const nlohmann::json::exception&) {
    return std::nullopt;
  }
  for (const auto& [name, sha256] : models) {
    if (TrackModelSha256(track.meta, name) != sha256) {
      if (miss != nullptr) *miss = ExistingTrackMiss::kOtherModels;
      return std::nullopt;
    }
  }
  track.lines.resize(frames);
  for (auto& [f, line] : ReadFrameLines(lines)) {
    if (f >= 0 && f < frames) track.lines[f] = std::move(line);
  }
  return track;
}

}  // namespace irbench
