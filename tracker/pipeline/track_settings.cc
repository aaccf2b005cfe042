#include "tracker/pipeline/track_settings.h"

#include <cctype>
#include <cstdio>

#include "common/error.h"
#include "common/json_reader.h"

namespace irbench {
namespace {

std::string RangeText(double min, double max) {
  char text[64];
  std::snprintf(text, sizeof(text), "must be in %g..%g", min, max);
  return text;
}

std::string ChoicesText(const std::vector<std::string>& choices) {
  std::string out;
  for (const std::string& c : choices) out += (out.empty() ? "" : ", ") + c;
  return out;
}

// The value as it would be typed, for error messages.
std::string ValueText(const nlohmann::json& value) {
  if (value.is_string()) return value.get<std::string>();
  if (value.is_number_float()) {
    char text[48];
    std::snprintf(text, sizeof(text), "%g", value.get<double>());
    return text;
  }
  return value.dump();
}

std::vector<TrackSetting> MakeSettings() {
  std::vector<TrackSetting> s;
  s.push_back({"stage", "--stage",
               "how far to go: pose (front end + particle-filter pose, joints and pointing) or\n"
               "features (silhouettes, axis points, hull only)",
               ChoiceBinding{{"features", "pose"},
                             [](const TrackerSettings& t) -> std::string {
                               return t.stage == TrackStage::kFeatures ? "features" : "pose";
                             },
                             [](TrackerSettings& t, const std::string& v) {
                               t.stage =
                                   v == "features" ? TrackStage::kFeatures : TrackStage::kPose;
                             }}});
  // The cap: each particle is scored against every camera's silhouette and
  // a fifth refined by ICP, every frame: measured 0.05-0.07 ms per particle
  // and frame on 2 cores (lab4, theater4), so 20000 is already 1-1.5 s a
  // frame; the thesis used 100.
  s.push_back({"particles", "--particles",
               "pose: particles of the filter (thesis 6.3), 1-20000 (capped: each costs about\n"
               "0.05-0.07 ms per frame on 2 cores, so 20000 is already over a second a frame)",
               IntBinding{[](TrackerSettings& t) -> int& { return t.pose.particles; }, 1, 20000}});
  s.push_back(
      {"refine_fraction", "--refine-fraction",
       "pose: share of the particles refined by 2D-3D ICP each frame (thesis 6.3.3)",
       DoubleBinding{[](TrackerSettings& t) -> double& { return t.pose.refine_fraction; }, 0, 1}});
  s.push_back(
      {"posture_proposal", "--posture-proposal",
       "pose: weight of the posture proposal (thesis 6.3.2: the arms moved into the posture recognised\n"
       "the frame-set before) beside the others' 1.0; 0: off (the default, docs/recognition.md)",
       DoubleBinding{[](TrackerSettings& t) -> double& { return t.pose.p_posture; }, 0, 1}});
  s.push_back({"seed", "--seed", "pose: seed of the filter's random stream",
               Uint64Binding{[](TrackerSettings& t) -> uint64_t& { return t.pose.seed; }}});
  s.push_back(
      {"rest_model", "--rest-model",
       "pose: rest-state SVM (default: tracker/models/rest_svm.yml when present)",
       PathBinding{[](TrackerSettings& t) -> std::filesystem::path& { return t.rest_model; }}});
  s.push_back(
      {"posture_atoms", "--posture-atoms",
       "posture atoms of the shape descriptor's decomposition (default: tracker/models/posture_atoms.json "
       "when present)",
       PathBinding{[](TrackerSettings& t) -> std::filesystem::path& { return t.posture_atoms; }}});
  s.push_back(
      {"gesture_models", "--gesture-models",
       "gesture models (default: tracker/models/gesture_models.json when present)",
       PathBinding{[](TrackerSettings& t) -> std::filesystem::path& { return t.gesture_models; }}});
  s.push_back({"gesture_model", "--gesture-model",
               "which gesture models recognise: fhmm (factorial), pahmm (parallel) or hmm (25 states)",
               ChoiceBinding{{"fhmm", "pahmm", "hmm"},
                             [](const TrackerSettings& t) -> std::string { return GestureModelKindName(t.gesture_model); },
                             [](TrackerSettings& t, const std::string& v) { t.gesture_model = *ParseGestureModelKind(v); }}});
  s.push_back({"motion_model", "--motion-model",
               "pose: which motion-label model labels the arms' motion (thesis 7.1): ldcrf, crf or none",
               ChoiceBinding{{"ldcrf", "crf", "none"},
                             [](const TrackerSettings& t) -> std::string {
                               return t.motion_model == MotionModelChoice::kNone ? "none"
                                      : t.motion_model == MotionModelChoice::kCrf ? "crf"
                                                                                   : "ldcrf";
                             },
                             [](TrackerSettings& t, const std::string& v) {
                               t.motion_model = v == "none" ? MotionModelChoice::kNone
                                                : v == "crf" ? MotionModelChoice::kCrf
                                                             : MotionModelChoice::kLdcrf;
                             }}});
  s.push_back(
      {"motion_labels", "--motion-labels",
       "pose: motion-label model file (default: tracker/models/motion_<--motion-model>.json when present)",
       PathBinding{[](TrackerSettings& t) -> std::filesystem::path& { return t.motion_labels; }}});
  s.push_back({"background_model", "--background-model",
               "flicker (light-following, pooled) or plain (the thesis's per-pixel Gaussian)",
               ChoiceBinding{{"flicker", "plain"},
                             [](const TrackerSettings& t) -> std::string {
                               return BackgroundKindName(t.frontend.background.model);
                             },
                             [](TrackerSettings& t, const std::string& v) {
                               t.frontend.background.model = *ParseBackgroundKind(v);
                             }}});
  s.push_back({"root_from_hull", "--root-from-model",
               "pose: report the model's root (under its waist) instead of the one measured on the\n"
               "hull's lower legs",
               BoolBinding{[](TrackerSettings& t) -> bool& { return t.pose.root_from_hull; }, false}});
  s.push_back({"heading_from_feet", "--heading-from-screen",
               "pose: a standing user is taken to face the screens, not the way the hull's feet point",
               BoolBinding{[](TrackerSettings& t) -> bool& { return t.pose.heading_from_feet; }, false}});
  s.push_back({"configure_shoulders", "--fixed-shoulders",
               "pose: keep the model's shoulder width a fixed proportion of the height instead of\n"
               "measuring it from straight arms held away from the body (thesis 6.1.1)",
               BoolBinding{[](TrackerSettings& t) -> bool& { return t.pose.configure_shoulders; }, false}});
  s.push_back({"nss", "--nss",
               "NSS skeletons (thesis 4.4.1) of the voxel hull every frame-set: labelled limb curves in\n"
               "features.jsonl and, with --ply, hull/NNNNNN_nss.ply (about 0.1-0.3 s a frame-set)",
               BoolBinding{[](TrackerSettings& t) -> bool& { return t.nss; }, true}});
  s.push_back(
      {"remove_shadows", "--keep-shadows", "skip the edge-based shadow removal",
       BoolBinding{[](TrackerSettings& t) -> bool& { return t.frontend.remove_shadows; }, false}});
  s.push_back(
      {"shadow_edge_scale", "--shadow-edge-scale",
       "shadow removal's edge thresholds times this, 0.25-8 (1: set for the thesis preset's\n"
       "washed-out images; 2 for the clean preset with --shadows on)",
       DoubleBinding{[](TrackerSettings& t) -> double& { return t.shadow_edge_scale; }, 0.25, 8}});
  s.push_back(
      {"hull_missing_views", "--hull-missing-views",
       "voxel hull: cameras allowed to disagree, 0 or 1 (0: the thesis's hull; 1 keeps what one "
       "view lost)",
       IntBinding{[](TrackerSettings& t) -> int& { return t.frontend.voxels.max_missing_views; }, 0,
                  1}});
  s.push_back(
      {"leave_out_faulty_cameras", "--keep-faulty-cameras",
       "use every camera's frame even when it is black or frozen (default: such a camera is left out\n"
       "while it is bad; a missing frame is always left out)",
       BoolBinding{[](TrackerSettings& t) -> bool& { return t.frontend.health.leave_out; }, false}});
  s.push_back(
      {"camera_dark_ratio", "--camera-dark-ratio",
       "a frame darker than this share of its camera's empty-stage mean (and under 16 grey levels) is\n"
       "a black camera, 0-0.9",
       DoubleBinding{[](TrackerSettings& t) -> double& { return t.frontend.health.dark_ratio; }, 0, 0.9}});
  s.push_back(
      {"camera_frozen_frames", "--camera-frozen-frames",
       "a camera repeating its frame this many times while others change is frozen, 1-1000",
       IntBinding{[](TrackerSettings& t) -> int& { return t.frontend.health.frozen_frames; }, 1, 1000}});
  return s;
}

}  // namespace

const std::vector<TrackSetting>& TrackSettings() {
  static const std::vector<TrackSetting> settings = MakeSettings();
  return settings;
}

const TrackSetting* FindTrackSetting(const std::string& key) {
  for (const TrackSetting& s : TrackSettings()) {
    if (s.key == key) return &s;
  }
  return nullptr;
}

nlohmann::json SettingValue(const TrackSetting& setting, const TrackerSettings& settings) {
  TrackerSettings t = settings;  // the bindings give mutable references; read a copy
  return std::visit(
      [&](const auto& b) -> nlohmann::json {
        using B = std::decay_t<decltype(b)>;
        if constexpr (std::is_same_v<B, ChoiceBinding>) {
          return b.get(settings);
        } else if constexpr (std::is_same_v<B, PathBinding>) {
          return b.ref(t).string();
        } else {
          return b.ref(t);
        }
      },
      setting.binding);
}

std::string SettingProblem(const TrackSetting& setting, const TrackerSettings& settings) {
  TrackerSettings t = settings;  // the bindings give mutable references; read a copy
  return std::visit(
      [&](const auto& b) -> std::string {
        using B = std::decay_t<decltype(b)>;
        if constexpr (std::is_same_v<B, IntBinding> || std::is_same_v<B, DoubleBinding>) {
          const double v = b.ref(t);
          return v >= b.min && v <= b.max ? "" : RangeText(b.min, b.max);
        } else if constexpr (std::is_same_v<B, ChoiceBinding>) {
          const std::string v = b.get(settings);
          for (const std::string& c : b.choices) {
            if (c == v) return "";
          }
          return "must be one of " + ChoicesText(b.choices);
        } else {
          return "";
        }
      },
      setting.binding);
}

void SetFromJson(const TrackSetting& setting, const JsonNode& node, TrackerSettings& settings) {
  std::visit(
      [&](const auto& b) {
        using B = std::decay_t<decltype(b)>;
        if constexpr (std::is_same_v<B, IntBinding>) {
          b.ref(settings) = node.Int();
        } else if constexpr (std::is_same_v<B, DoubleBinding>) {
          b.ref(settings) = node.Number();
        } else if constexpr (std::is_same_v<B, Uint64Binding>) {
          if (!node.raw().is_number_unsigned()) node.Fail("expected an unsigned integer");
          b.ref(settings) = node.raw().get<uint64_t>();
        } else if constexpr (std::is_same_v<B, BoolBinding>) {
          b.ref(settings) = node.Bool();
        } else if constexpr (std::is_same_v<B, PathBinding>) {
          b.ref(settings) = node.String();
        } else {
          const std::string v = node.String();
          bool known = false;
          for (const std::string& c : b.choices) known = known || c == v;
          if (!known) node.Fail("must be one of " + ChoicesText(b.choices));
          b.set(settings, v);
        }
      },
      setting.binding);
  if (const std::string problem = SettingProblem(setting, settings); !problem.empty())
    node.Fail(problem);
}

void SetFromText(const TrackSetting& setting, const std::string& text, TrackerSettings& settings) {
  const auto fail = [&](const std::string& problem) {
    throw InputError("", setting.flag, "'" + text + "': " + problem);
  };
  std::visit(
      [&](const auto& b) {
        using B = std::decay_t<decltype(b)>;
        size_t used = 0;
        try {
          if constexpr (std::is_same_v<B, IntBinding>) {
            b.ref(settings) = std::stoi(text, &used);
          } else if constexpr (std::is_same_v<B, DoubleBinding>) {
            b.ref(settings) = std::stod(text, &used);
          } else if constexpr (std::is_same_v<B, Uint64Binding>) {
            if (text.find_first_not_of("0123456789") != std::string::npos)
              fail("expected an unsigned integer");
            b.ref(settings) = std::stoull(text, &used);
          } else if constexpr (std::is_same_v<B, BoolBinding>) {
            if (text != "true" && text != "false") fail("expected true or false");
            b.ref(settings) = text == "true";
            used = text.size();
          } else if constexpr (std::is_same_v<B, PathBinding>) {
            b.ref(settings) = text;
            used = text.size();
          } else {
            bool known = false;
            for (const std::string& c : b.choices) known = known || c == text;
            if (!known) fail("must be one of " + ChoicesText(b.choices));
            b.set(settings, text);
            used = text.size();
          }
        } catch (const std::logic_error&) {  // std::invalid_argument, std::out_of_range
          fail(std::is_same_v<B, DoubleBinding> ? "expected a number"
                                                : "expected an integer in range");
        }
        if (used != text.size()) fail("expected a number");
      },
      setting.binding);
  if (const std::string problem = SettingProblem(setting, settings); !problem.empty())
    fail(problem);
}

std::string DefaultText(const TrackSetting& setting) {
  return ValueText(SettingValue(setting, TrackerSettings()));
}

std::string TypeName(const TrackSetting& setting) {
  return std::visit(
      [](const auto& b) -> std::string {
        using B = std::decay_t<decltype(b)>;
        if constexpr (std::is_same_v<B, IntBinding>) return "INT";
        if constexpr (std::is_same_v<B, Uint64Binding>) return "UINT";
        if constexpr (std::is_same_v<B, DoubleBinding>) return "FLOAT";
        if constexpr (std::is_same_v<B, PathBinding>) return "PATH";
        if constexpr (std::is_same_v<B, ChoiceBinding>) return "TEXT";
        return "";
      },
      setting.binding);
}

void CheckTrackerSettings(const TrackerSettings& settings) {
  for (const TrackSetting& s : TrackSettings()) {
    if (const std::string problem = SettingProblem(s, settings); !problem.empty()) {
      throw InputError("", s.flag, "'" + ValueText(SettingValue(s, settings)) + "': " + problem);
    }
  }
  EffectiveFrontEndOptions(settings).Check();  // the options the front end runs with
  settings.pose.Check();
}

nlohmann::json SettingsJson(const TrackerSettings& settings) {
  nlohmann::json j = nlohmann::json::object();
  for (const TrackSetting& s : TrackSettings()) j[s.key] = SettingValue(s, settings);
  return j;
}

std::string NonDefaultSettingsTag(const TrackerSettings& settings) {
  const TrackerSettings defaults;
  std::string tag;
  for (const TrackSetting& s : TrackSettings()) {
    const nlohmann::json value = SettingValue(s, settings);
    if (value == SettingValue(s, defaults)) continue;
    std::string text = ValueText(value);
    if (std::holds_alternative<PathBinding>(s.binding)) {
      // A path: its file name and a hash of the whole, to keep the tag short.
      uint32_t hash = 2166136261u;  // FNV-1a
      for (unsigned char c : text) hash = (hash ^ c) * 16777619u;
      char hex[16];
      std::snprintf(hex, sizeof(hex), "%08x", hash);
      text = std::filesystem::path(text).stem().string().substr(0, 32) + "_" + hex;
    }
    tag += (tag.empty() ? "" : "-") + s.key + "=" + text;
  }
  for (char& c : tag) {
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '.' && c != '=' && c != '-' &&
        c != '_')
      c = '_';
  }
  return tag;
}

FrontEndOptions EffectiveFrontEndOptions(const TrackerSettings& settings) {
  FrontEndOptions options = settings.frontend;
  options.shadow.canny_low *= settings.shadow_edge_scale;
  options.shadow.canny_high *= settings.shadow_edge_scale;
  return options;
}

}  // namespace irbench
