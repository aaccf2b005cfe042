#pragma once
// A sequence folder's manifest.json (irbench.sequence/1; its fields in
// docs/architecture.md): what was rendered, with which inputs and seed. The
// sim writes it last, so its presence marks a complete folder; the harness
// and tests read it. The tracker never does (a real rig has no manifest).

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace irbench {

inline constexpr char kManifestFile[] = "manifest.json";
inline constexpr char kSequenceFormat[] = "irbench.sequence/1";

// The keys both the writer (sim/sequence/render_job.cc) and the reader use.
namespace manifest_key {
inline constexpr char kFormat[] = "format";
inline constexpr char kSeed[] = "seed";
inline constexpr char kScene[] = "scene";
inline constexpr char kRig[] = "rig";
inline constexpr char kAvatar[] = "avatar";
inline constexpr char kMotion[] = "motion";
inline constexpr char kSensor[] = "sensor";  // the preset's name
inline constexpr char kFps[] = "fps";
inline constexpr char kFrameCount[] = "frame_count";
inline constexpr char kCameras[] = "cameras";
inline constexpr char kJoints[] = "joints";
inline constexpr char kName[] = "name";  // of scene, rig, avatar, motion
}  // namespace manifest_key

// The fields the readers use, typed; `json` holds the whole file.
struct Manifest {
  uint64_t seed = 0;
  double fps = 0;
  int frame_count = 0;
  std::vector<std::string> cameras;  // rig order
  std::vector<std::string> joints;   // the truth's joint names, in order
  // The names of what was rendered: scene, rig, avatar, motion (each's
  // `name`) and the sensor preset; "" where absent.
  std::string scene, rig, avatar, motion, sensor;
  nlohmann::json json;
};

// True when `sequence_dir` holds a manifest (a complete sequence folder).
bool HasManifest(const std::filesystem::path& sequence_dir);
// Writes `manifest` (which must carry "format": kSequenceFormat) atomically.
void WriteManifest(const std::filesystem::path& sequence_dir, const nlohmann::json& manifest);
// Reads and checks manifest.json; InputError naming the file and field when it
// is missing, not JSON, of another format or a field has the wrong type.
Manifest ReadManifest(const std::filesystem::path& sequence_dir);

}  // namespace irbench
