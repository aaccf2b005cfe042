#include "ci/suite_runner/suite.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <mutex>
#include <thread>
#include <nlohmann/json.hpp>
#include <fstream>
#include <sstream>

#include "ci/score/score.h"
#include "ci/score/score_job.h"
#include "common/atomic_file.h"
#include "common/error.h"
#include "common/json_reader.h"
#include "common/logging.h"
#include "common/progress.h"
#include "common/paths.h"
#include "sequence_format/manifest.h"
#include "sim/sequence/render_job.h"
#include "tracker/pipeline/track_job.h"

namespace irbench {
namespace fs = std::filesystem;
namespace {

struct Bound {
  std::string kind;  // "max" or "min"
  double value = 0;
  double tolerance = 0;  // allowed drift from the baseline, absolute
};

struct Scenario {
  std::string name;
  RenderJobOptions render;
  TrackerSettings tracker;  // the scenario's `track` object: keys of TrackSettings()
  std::map<std::string, Bound> thresholds;
};

// The metrics a threshold may name: see suite.h.
const std::vector<std::string>& KnownMetrics() {
  static const std::vector<std::string> m = [] {
    std::vector<std::string> out = {"silhouette_iou_median", "tracked_fraction", "arms_mean_cm",
                                    "pointing_mean_deg", "rest_accuracy"};
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

std::vector<Scenario> ReadSuite(const fs::path& file, std::string* name) {
  const JsonNode root = ParseJsonFile(file.string());
  root.CheckKeys({"format", "name", "description", "scenarios"});
  if (root.GetString("format") != "irbench.suite/1") root["format"].Fail("expected \"irbench.suite/1\"");
  *name = root.GetString("name", file.stem().string());
  std::vector<Scenario> out;
  const JsonNode list = root["scenarios"];
  if (list.Size() == 0) list.Fail("no scenarios");
  for (size_t i = 0; i < list.Size(); ++i) {
    const JsonNode s = list[i];
    s.CheckKeys({"name", "scene", "rig", "avatar", "motion", "sensor", "seed", "frames", "background_frames",
                 "background_screen_sweep", "track", "thresholds"});
    Scenario sc;
    sc.name = s.GetString("name");
    for (const Scenario& other : out) {
      if (other.name == sc.name) s["name"].Fail("'" + sc.name + "' appears twice");
    }
    sc.render.scene = s.GetString("scene", "");
    sc.render.rig = s.GetString("rig", "theater4");
    sc.render.avatar = s.GetString("avatar", "p1");
    sc.render.motion = s.GetString("motion", "demo");
    sc.render.sensor = s.GetString("sensor", "thesis");
    sc.render.seed = static_cast<uint64_t>(s.GetInt("seed", 1));
    if (s.Has("frames")) {
      sc.render.frames = s.GetInt("frames");
      if (*sc.render.frames < 1) s["frames"].Fail("must be at least 1");
    }
    sc.render.background_frames = s.GetInt("background_frames", 12);
    if (sc.render.background_frames < 2) s["background_frames"].Fail("the tracker needs at least 2");
    sc.render.screen_sweep = s.GetBool("background_screen_sweep", true);
    if (s.Has("track")) ReadTrackerSettings(s["track"], file, sc.tracker);
    const JsonNode th = s["thresholds"];
    for (const auto& [metric, value] : th.raw().items()) {
      if (std::find(KnownMetrics().begin(), KnownMetrics().end(), metric) == KnownMetrics().end()) {
        th[metric].Fail("unknown metric (" + KnownMetricsText() + ")");
      }
      const JsonNode b = th[metric];
      b.CheckKeys({"max", "min", "tolerance"});
      Bound bound;
      if (b.Has("max") == b.Has("min")) b.Fail("give exactly one of max or min");
      bound.kind = b.Has("max") ? "max" : "min";
      bound.value = b.GetDouble(bound.kind);
      bound.tolerance = b.GetDouble("tolerance", 0.0);
      if (bound.tolerance < 0) b["tolerance"].Fail("must be >= 0");
      sc.thresholds[metric] = bound;
    }
    out.push_back(sc);
  }
  return out;
}

std::string Number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.4g", v);
  return buf;
}

// The files a scenario's render reads (validated, names resolved).
std::vector<fs::path> ScenarioInputFiles(const RenderJobOptions& r) {
  const RenderInputs in = LoadRenderInputs(r);
  return {in.rig_file, in.scene_file, in.avatar_file, in.motion_file};
}

// The render inputs that decide the frames, hashed with the tool version and
// the contents of the files they name.
std::string CacheKey(const RenderJobOptions& r) {
  const RenderInputs in = LoadRenderInputs(r);  // validates, resolves names to files
  std::string key = ToolVersion() + "|" + r.rig + "|" + r.scene + "|" + r.avatar + "|" + r.motion + "|" + r.sensor +
                    "|" + std::to_string(r.seed) + "|" + std::to_string(r.frames.value_or(-1)) + "|" +
                    std::to_string(r.background_frames) + "|" + std::to_string(r.supersample) +
                    (SweepsScreens(r, in) ? "|sweep" : "");
  for (const fs::path& f : {in.rig_file, in.scene_file, in.avatar_file, in.motion_file}) {
    if (f.empty() || !fs::is_regular_file(f)) continue;
    std::ifstream file(f, std::ios::binary);
    key += std::string((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  }
  char hex[20];
  std::snprintf(hex, sizeof(hex), "%016llx", static_cast<unsigned long long>(Fnv1a64(key)));
  return hex;
}

// What one scenario measured, in the order of its thresholds.
std::map<std::string, double> RunScenario(const Scenario& sc, const std::string& suite, const fs::path& cache,
                                          std::mutex* render_mutex, fs::path* report) {
  const auto start = std::chrono::steady_clock::now();
  // Render, or reuse the cached frames of the same inputs. One render at a
  // time: each render job owns the process's GL display while it runs.
  RenderJobOptions render = sc.render;
  const fs::path seq = cache / (sc.name + "-" + CacheKey(render));
  {
    std::lock_guard<std::mutex> lock(*render_mutex);
    if (!HasManifest(seq)) {
      Log().info("suite {}: {}: rendering", suite, sc.name);
      render.out = seq;
      render.overwrite = true;
      RunRenderJob(render);
    } else {
      Log().info("suite {}: {}: rendered before (cache {})", suite, sc.name, seq.filename().string());
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
  std::map<std::string, double> metrics;
  metrics["silhouette_iou_median"] = score.silhouettes ? score.silhouettes->All().iou_median : 0.0;
  metrics["tracked_fraction"] = score.present_frames ? double(score.tracked_frames) / score.present_frames : 0.0;
  double arms = 0;
  int arm_joints = 0;
  for (const std::string& joint : ScoredJoints()) {
    const ErrorStats& e = score.joints.at(joint);
    if (e.total == 0) continue;
    metrics[joint + "_mean_cm"] = e.mean;
    if (joint.find("shoulder") != std::string::npos || joint.find("elbow") != std::string::npos ||
        joint.find("wrist") != std::string::npos) {
      arms += e.mean;
      ++arm_joints;
    }
  }
  if (arm_joints) metrics["arms_mean_cm"] = arms / arm_joints;
  // Pointing: the kept samples of both hands together.
  double pointing = 0;
  int kept = 0;
  for (const auto& [hand, e] : score.pointing) {
    pointing += e.mean * (e.total - e.outliers);
    kept += e.total - e.outliers;
  }
  if (kept) metrics["pointing_mean_deg"] = pointing / kept;
  if (const auto it = score.rest.find("both"); it != score.rest.end() && it->second.total) {
    metrics["rest_accuracy"] = it->second.rate();
  }
  Log().info("suite {}: {}: done in {:.0f} s", suite, sc.name,
             std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  return metrics;
}

}  // namespace

std::string SuiteResult::Table() const {
  std::ostringstream out;
  out << "| scenario | metric | value | threshold | baseline | result |\n|---|---|---|---|---|---|\n";
  for (const MetricResult& r : rows) {
    out << "| " << r.scenario << " | " << r.metric << " | " << Number(r.value) << " | " << r.bound << " | "
        << r.baseline << " | " << (r.pass ? "pass" : "**FAIL**: " + r.why) << " |\n";
  }
  return out.str();
}

SuiteResult RunSuite(const SuiteRunOptions& options) {
  fs::path file = options.suite;
  if (!fs::is_regular_file(file)) file = ResolveDataFile("ci/suites", options.suite.string(), "SUITE");
  SuiteResult result;
  const std::vector<Scenario> scenarios = ReadSuite(file, &result.name);
  const fs::path baselines_dir = options.baselines.empty() ? DataRoot() / "ci" / "baselines" : options.baselines;
  const fs::path baseline_file = baselines_dir / (result.name + ".json");
  nlohmann::json baseline = nlohmann::json::object();
  if (fs::is_regular_file(baseline_file)) baseline = ParseJsonFile(baseline_file.string()).raw();
  const fs::path cache = options.cache.empty() ? OutputRoot() / "renders" / "cache" : options.cache;
  // The cache holds what the suite writes; it may not hold or lie in what it
  // reads (the suite file, the baselines, the scenarios' data files).
  std::vector<fs::path> inputs = {file, baselines_dir};
  for (const Scenario& sc : scenarios) {
    for (const fs::path& f : ScenarioInputFiles(sc.render)) inputs.push_back(f);
  }
  CheckOutputApart(cache, inputs, "--cache");
  fs::create_directories(cache);
  // Scenarios in parallel, up to --jobs workers (default: the core count).
  const unsigned cores = std::max(1u, std::thread::hardware_concurrency());
  const size_t workers = std::min<size_t>(scenarios.size(), options.jobs > 0 ? size_t(options.jobs) : cores);
  Log().info("suite {}: {} scenario(s), {} at a time", result.name, scenarios.size(), workers);
  std::vector<std::map<std::string, double>> measured(scenarios.size());
  std::vector<std::exception_ptr> errors(scenarios.size());
  std::vector<fs::path> reports(scenarios.size());
  std::atomic<size_t> next{0};
  std::mutex render_mutex;
  // One progress line for the suite; the scenarios' renders and tracks run
  // on several threads and keep theirs quiet.
  const QuietProgress quiet;
  Progress progress("suite " + result.name, "scenarios", static_cast<int>(scenarios.size()));
  progress.IgnoreQuiet();
  std::mutex progress_mutex;
  int finished = 0;
  const auto work = [&] {
    for (size_t i; (i = next++) < scenarios.size();) {
      try {
        Log().debug("suite {}: scenario {}/{}: {}", result.name, i + 1, scenarios.size(), scenarios[i].name);
        measured[i] = RunScenario(scenarios[i], result.name, cache, &render_mutex, &reports[i]);
        const std::lock_guard<std::mutex> lock(progress_mutex);
        progress.Set(++finished, "scenarios done");
      } catch (...) {
        errors[i] = std::current_exception();
        next = scenarios.size();  // start no more
      }
    }
  };
  std::vector<std::thread> pool;
  for (size_t w = 1; w < workers; ++w) pool.emplace_back(work);
  work();
  for (std::thread& t : pool) t.join();
  for (const std::exception_ptr& e : errors) {
    if (e) std::rethrow_exception(e);
  }

  nlohmann::json blessed = nlohmann::json::object();
  for (size_t i = 0; i < scenarios.size(); ++i) {
    const Scenario& sc = scenarios[i];
    const std::map<std::string, double>& metrics = measured[i];
    result.reports.emplace_back(sc.name, reports[i]);
    for (const auto& [metric, bound] : sc.thresholds) {
      MetricResult r;
      r.scenario = sc.name;
      r.metric = metric;
      r.bound = bound.kind + " " + Number(bound.value);
      const auto it = metrics.find(metric);
      if (it == metrics.end()) {
        r.pass = false;
        r.why = "not measured (nothing scored)";
        result.rows.push_back(r);
        continue;
      }
      r.value = it->second;
      blessed[sc.name][metric] = r.value;
      const bool higher_better = bound.kind == "min";
      if (higher_better ? r.value < bound.value : r.value > bound.value) {
        r.pass = false;
        r.why = "beyond the threshold";
      }
      if (baseline.contains(sc.name) && baseline[sc.name].contains(metric) && baseline[sc.name][metric].is_number()) {
        const double base = baseline[sc.name][metric];
        r.baseline = Number(base) + " ± " + Number(bound.tolerance);
        const bool worse = higher_better ? r.value < base - bound.tolerance : r.value > base + bound.tolerance;
        if (worse && !options.bless) {
          r.pass = false;
          r.why = r.why.empty() ? "regressed from the baseline" : r.why + "; regressed from the baseline";
        }
      } else {
        r.baseline = "none";
      }
      result.rows.push_back(r);
    }
  }
  for (const MetricResult& r : result.rows) result.pass &= r.pass;
  if (options.bless) {
    fs::create_directories(baselines_dir);
    AtomicWriteFile(baseline_file, blessed.dump(2) + "\n");
    Log().info("suite {}: baseline written to {}", result.name, baseline_file.string());
  }
  return result;
}

}  // namespace irbench
