#pragma once
// The tracker's settings, each declared once: its key (the suites'
// `track.<key>` and track.json's), command-line flag, help, default (the
// option struct's own initialiser) and range. `irbench track` (cli/), the
// suites (ci/suite_runner/) and track.json all bind from TrackSettings(); a new
// setting is one entry here (and, when it is new, its field in the option
// struct it belongs to).

#include <cstdint>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "common/json_reader.h"
#include "tracker/frontend/frontend.h"
#include "tracker/gesture/gesture_models.h"
#include "tracker/motion_labels/motion_label_model.h"
#include "tracker/pose/pose_tracker.h"

namespace irbench {

// What `irbench track` runs: the front end alone, or the pose tracker after it.
enum class TrackStage { kFeatures, kPose };

// Which motion-label model labels the arms (thesis 7.1), or none.
enum class MotionModelChoice { kLdcrf, kCrf, kNone };

// Everything that decides what the tracker computes (not where it writes).
struct TrackerSettings {
  TrackStage stage = TrackStage::kPose;
  FrontEndOptions frontend;
  // Shadow removal's Canny thresholds (ShadowOptions) times this: they are
  // set for the washed-out `thesis` images; images of more contrast with
  // soft shadows (the `clean` preset with --shadows on: 2) need them higher,
  // or the penumbra next to the feet passes as an edge (docs/tracker.md).
  double shadow_edge_scale = 1.0;
  PoseTrackerOptions pose;
  // pose: the rest-state SVM (irbench train rest); empty: the default model
  // (tracker/models/rest_svm.yml) when it exists, else rest stays null.
  std::filesystem::path rest_model;
  // The posture atoms (irbench train atoms); empty: the default model
  // (tracker/models/posture_atoms.json) when it exists, else posture stays null.
  std::filesystem::path posture_atoms;
  // The gesture models (irbench train gestures) and which kind recognises;
  // empty path: the default model (tracker/models/gesture_models.json) when
  // it and the posture atoms exist, else gesture stays null.
  std::filesystem::path gesture_models;
  GestureModelKind gesture_model = GestureModelKind::kFactorialHmm;
  // pose: the motion-label model (irbench train motion-labels); empty path:
  // tracker/models/motion_<motion_model>.json when it exists, else motion
  // stays null.
  std::filesystem::path motion_labels;
  MotionModelChoice motion_model = MotionModelChoice::kLdcrf;
  // NSS skeletons (thesis 4.4.1) of the voxel hull every frame-set: limb
  // curves in features.jsonl (`nss`) and, with --ply, hull/NNNNNN_nss.ply.
  bool nss = false;
};

// The binding kinds. `ref` gives the setting's field in a TrackerSettings.
struct IntBinding {
  int& (*ref)(TrackerSettings&);
  int min, max;
};
struct Uint64Binding {
  uint64_t& (*ref)(TrackerSettings&);
};
struct DoubleBinding {
  double& (*ref)(TrackerSettings&);
  double min, max;
};
// A bool; on the command line a flag that sets it to `flag_value`.
struct BoolBinding {
  bool& (*ref)(TrackerSettings&);
  bool flag_value;
};
// One of named values, stored as a string or an enum through get/set.
struct ChoiceBinding {
  std::vector<std::string> choices;
  std::string (*get)(const TrackerSettings&);
  void (*set)(TrackerSettings&, const std::string&);
};
struct PathBinding {
  std::filesystem::path& (*ref)(TrackerSettings&);
};

struct TrackSetting {
  std::string key;   // suite key (track.<key>) and track.json key
  std::string flag;  // irbench track's option, e.g. "--particles"
  std::string help;
  std::variant<IntBinding, Uint64Binding, DoubleBinding, BoolBinding, ChoiceBinding, PathBinding>
      binding;
};

// Every tracker setting, in the order of `irbench track --help`.
const std::vector<TrackSetting>& TrackSettings();
// The setting named `key`; nullptr when there is none.
const TrackSetting* FindTrackSetting(const std::string& key);

// The setting's value as JSON (track.json, the suites' folder names).
nlohmann::json SettingValue(const TrackSetting& setting, const TrackerSettings& settings);
// What is wrong with the setting's value ("must be in 1..100000"), or "".
std::string SettingProblem(const TrackSetting& setting, const TrackerSettings& settings);
// Sets the setting from a JSON value; InputError (naming `node`'s file and
// field) on a wrong type, an unknown choice or a value out of range.
void SetFromJson(const TrackSetting& setting, const JsonNode& node, TrackerSettings& settings);
// Sets the setting from text as typed on a command line ("100", "pose");
// InputError naming the flag when it does not parse or is out of range.
void SetFromText(const TrackSetting& setting, const std::string& text, TrackerSettings& settings);
// The setting's default as text (for --help; "" for an empty path).
std::string DefaultText(const TrackSetting& setting);
// "INT", "UINT", "FLOAT", "TEXT", "PATH" or "" for a flag.
std::string TypeName(const TrackSetting& setting);

// Checks every setting and the libraries' options built from them; throws
// InputError naming the flag ("--particles: '0': must be in 1..100000").
void CheckTrackerSettings(const TrackerSettings& settings);
// Every setting by key, for track.json.
nlohmann::json SettingsJson(const TrackerSettings& settings);
// The settings that differ from the defaults, as "<key>=<value>" joined by
// "-", for folder names ("" when all are default).
std::string NonDefaultSettingsTag(const TrackerSettings& settings);

// The front end's options with the job-level settings applied (the edge scale).
FrontEndOptions EffectiveFrontEndOptions(const TrackerSettings& settings);

}  // namespace irbench
