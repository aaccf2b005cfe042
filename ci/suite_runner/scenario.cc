#include "ci/suite_runner/scenario.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <string_view>

#include "ci/score/score.h"
#include "ci/score/score_job.h"
#include "common/atomic_file.h"
#include "common/error.h"
#include "common/file_bytes.h"
#include "common/logging.h"
#include "common/paths.h"
#include "sequence_format/manifest.h"
#include "sim/motion/retarget.h"
#include "tracker/pipeline/track_job.h"

namespace irbench {
namespace fs = std::filesystem;
namespace {

// A scenario's `track` object: any setting of TrackSettings() by its key; a
// relative path (rest_model) is relative to the suite file's folder.
void ReadTrackerSettings(const JsonNode& t, const fs::path& suite_file, TrackerSettings& settings) {
  std::vector<std::string> keys;
  for (const TrackSetting& setting : TrackSettings()) keys.push_back(setting.key);
  t.CheckKeys(keys);
  for (const TrackSetting& setting : TrackSettings()) {
    if (!t.Has(setting.key)) continue;
    SetFromJson(setting, t[setting.key], settings);
    if (const auto* path = std::get_if<PathBinding>(&setting.binding)) {
      fs::path& value = path->ref(settings);
      if (!value.empty() && value.is_relative()) value = suite_file.parent_path() / value;
    }
  }
}

// A scenario's motion: a library or motions/ name as it stands; a motion file
// (a path with a folder or an extension) relative to the suite file's folder.
std::string ScenarioMotion(const std::string& motion, const fs::path& suite_file) {
  const fs::path as_path(motion);
  const bool looks_like_path = motion.find('/') != std::string::npos || as_path.has_extension();
  if (!looks_like_path || as_path.is_absolute()) return motion;
  return (suite_file.parent_path() / as_path).lexically_normal().string();
}

// A file given by its path counts in a cache key by its file name only.
std::string KeyName(const std::string& name_or_path) {
  const fs::path as_path(name_or_path);
  const bool is_path = name_or_path.find('/') != std::string::npos || as_path.has_extension();
  return is_path ? as_path.filename().string() : name_or_path;
}

}  // namespace

const std::vector<std::string>& ScenarioKeys() {
  static const std::vector<std::string> keys = {"scene", "rig", "avatar", "motion", "optional", "max_seconds",
                                                "sensor", "seed", "frames", "background_frames",
                                                "background_screen_sweep", "track"};
  return keys;
}

void ReadScenarioKeys(const JsonNode& s, const fs::path& file, Scenario* out) {
  Scenario& sc = *out;
  sc.file = file.string();
  sc.render.scene = s.GetString("scene", "");
  sc.render.rig = s.GetString("rig", "theater4");
  sc.render.avatar = s.GetString("avatar", "p1");
  sc.render.motion = ScenarioMotion(s.GetString("motion", "demo"), file);
  sc.optional = s.GetBool("optional", false);
  const bool motion_is_file = sc.render.motion.find('/') != std::string::npos || fs::path(sc.render.motion).has_extension();
  if (sc.optional && motion_is_file && !fs::is_regular_file(sc.render.motion)) {
    sc.missing = "no motion file " + sc.render.motion;
  }
  sc.render.sensor = s.GetString("sensor", "thesis");
  sc.render.seed = static_cast<uint64_t>(s.GetInt("seed", 1));
  if (s.Has("frames") && s.Has("max_seconds")) s["max_seconds"].Fail("give frames or max_seconds, not both");
  if (s.Has("frames")) {
    sc.render.frames = s.GetInt("frames");
    if (*sc.render.frames < 1) s["frames"].Fail("must be at least 1");
  }
  if (s.Has("max_seconds")) {
    const double max_s = s.GetDouble("max_seconds");
    if (!(max_s > 0 && max_s <= 3600)) s["max_seconds"].Fail("must be in (0, 3600]");
    if (sc.missing.empty()) {
      // The motion's own length, cut at max_seconds of the rig's frame rate.
      const RenderInputs in = LoadRenderInputs(sc.render);
      sc.render.frames = std::max(1, std::min(in.frame_count, static_cast<int>(std::floor(max_s * in.fps + 1e-9))));
    }
  }
  sc.render.background_frames = s.GetInt("background_frames", 12);
  if (sc.render.background_frames < 2) s["background_frames"].Fail("the tracker needs at least 2");
  sc.render.screen_sweep = s.GetBool("background_screen_sweep", true);
  if (s.Has("track")) ReadTrackerSettings(s["track"], file, sc.tracker);
}

const std::vector<std::string>& KnownMetrics() {
  static const std::vector<std::string> m = [] {
    std::vector<std::string> out = {"silhouette_iou_median", "tracked_fraction", "arms_mean_cm",
                                    "pointing_mean_deg", "rest_accuracy", "posture_accuracy",
                                    "gesture_identification", "motion_mean_recall"};
    for (const std::string& joint : ScoredJoints()) out.push_back(joint + "_mean_cm");
    return out;
  }();
  return m;
}

std::string KnownMetricsText() {
  std::string out;
  for (const std::string& m : KnownMetrics()) out += (out.empty() ? "" : ", ") + m;
  return out;
}

bool HigherIsBetter(const std::string& metric) {
  const auto ends_with = [&](std::string_view tail) {
    return metric.size() >= tail.size() && metric.compare(metric.size() - tail.size(), tail.size(), tail) == 0;
  };
  return !ends_with("_cm") && !ends_with("_deg");
}

std::vector<fs::path> ScenarioInputFiles(const RenderJobOptions& r) {
  const RenderInputs in = LoadRenderInputs(r);
  return {in.rig_file, in.scene_file, in.avatar_file, in.motion_file};
}

std::string CacheKey(const RenderJobOptions& r) {
  const RenderInputs in = LoadRenderInputs(r);  // validates, resolves names to files
  // A file given by its path by its file name: its contents are in the key,
  // its folder is not. Names stay as they are.
  std::string key = ToolVersion() + "|" + KeyName(r.rig) + "|" + KeyName(r.scene) + "|" + KeyName(r.avatar) + "|" +
                    KeyName(r.motion) + "|" + r.sensor +
                    "|" + std::to_string(r.seed) + "|" + std::to_string(r.frames.value_or(-1)) + "|" +
                    std::to_string(r.background_frames) + "|" + std::to_string(r.supersample) +
                    (SweepsScreens(r, in) ? "|sweep" : "");
  // Motion capture is retargeted on load: its revision counts (for a session,
  // when it names a capture file).
  bool mocap = in.motion_kind == "bvh" || in.motion_kind == "amc";
  if (in.motion_kind == "session" && fs::is_regular_file(in.motion_file)) {
    const std::string text = ReadFileBytes(in.motion_file);
    mocap = text.find(".bvh") != std::string::npos || text.find(".amc") != std::string::npos;
  }
  if (mocap) key += "|retarget " + std::to_string(kRetargetRevision);
  for (const fs::path& f : {in.rig_file, in.scene_file, in.avatar_file, in.motion_file}) {
    if (f.empty() || !fs::is_regular_file(f)) continue;
    key += ReadFileBytes(f);
  }
  char hex[20];
  std::snprintf(hex, sizeof(hex), "%016llx", static_cast<unsigned long long>(Fnv1a64(key)));
  return hex;
}

Measured RunScenario(const Scenario& sc, const std::string& label, const fs::path& cache, std::mutex* render_mutex,
                     fs::path* report) {
  const auto start = std::chrono::steady_clock::now();
  // Render, or reuse the cached frames of the same inputs. One render at a
  // time: each render job owns the process's GL display while it runs.
  RenderJobOptions render = sc.render;
  const fs::path seq = cache / (sc.name + "-" + CacheKey(render));
  {
    std::lock_guard<std::mutex> lock(*render_mutex);
    if (!HasManifest(seq)) {
      Log().info("{}: {}: rendering", label, sc.name);
      render.out = seq;
      render.overwrite = true;
      RunRenderJob(render);
    } else {
      Log().info("{}: {}: rendered before (cache {})", label, sc.name, seq.filename().string());
    }
  }
  TrackJobOptions track;
  track.sequence = seq;
  track.tracker = sc.tracker;
  // The folder names the settings that differ from the defaults.
  const std::string tag = NonDefaultSettingsTag(sc.tracker);
  track.out = seq / (tag.empty() ? std::string("track") : "track-" + tag);
  track.overwrite = true;
  RunTrackJob(track);
  ScoreJobOptions job;
  job.sequence = seq;
  job.track = track.out / "track.jsonl";
  job.out = seq / ("score-" + track.out.filename().string());
  job.overwrite = true;
  Score score;
  *report = RunScoreJob(job, nullptr, &score) / "report.html";
  Measured out;
  const std::string kind = ReadManifest(seq).json[manifest_key::kMotion].value("kind", "");
  out.group = kind == "bvh" || kind == "amc" ? "mocap" : "library";
  out.person = sc.render.avatar;
  std::map<std::string, double>& metrics = out.metrics;
  metrics["silhouette_iou_median"] = score.silhouettes ? score.silhouettes->All().iou_median : 0.0;
  metrics["tracked_fraction"] = score.present_frames ? double(score.tracked_frames) / score.present_frames : 0.0;
  out.weights["tracked_fraction"] = score.present_frames;
  double arms = 0;
  int arm_joints = 0;
  for (const std::string& joint : ScoredJoints()) {
    const ErrorStats& e = score.joints.at(joint);
    if (e.total == 0) continue;
    metrics[joint + "_mean_cm"] = e.mean;
    out.weights[joint + "_mean_cm"] = e.total - e.outliers;
    if (joint.find("shoulder") != std::string::npos || joint.find("elbow") != std::string::npos ||
        joint.find("wrist") != std::string::npos) {
      arms += e.mean;
      ++arm_joints;
    }
  }
  // Recognition (thesis 5.1, 5.3), when the tracker had the models.
  if (score.posture.total > 0) {
    metrics["posture_accuracy"] = score.posture.rate();
    out.weights["posture_accuracy"] = score.posture.total;
  }
  if (score.gesture.total > 0) {
    metrics["gesture_identification"] = score.gesture.rate();
    out.weights["gesture_identification"] = score.gesture.total;
  }
  if (score.motion.total > 0) {
    metrics["motion_mean_recall"] = MeanRecall(score.motion_confusion);
    out.weights["motion_mean_recall"] = score.motion.total;
  }
  if (arm_joints) metrics["arms_mean_cm"] = arms / arm_joints;
  // Pointing: the kept samples of both hands together.
  double pointing = 0;
  int kept = 0;
  for (const auto& [hand, e] : score.pointing) {
    pointing += e.mean * (e.total - e.outliers);
    kept += e.total - e.outliers;
  }
  if (kept) {
    metrics["pointing_mean_deg"] = pointing / kept;
    out.weights["pointing_mean_deg"] = kept;
  }
  if (const auto it = score.rest.find("both"); it != score.rest.end() && it->second.total) {
    metrics["rest_accuracy"] = it->second.rate();
    out.weights["rest_accuracy"] = it->second.total;
  }
  Log().info("{}: {}: done in {:.0f} s", label, sc.name,
             std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  return out;
}

}  // namespace irbench
