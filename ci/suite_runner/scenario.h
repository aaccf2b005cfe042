#pragma once
// One closed-loop scenario — scene, rig, person, motion, sensor preset, seed,
// frames, tracker settings — as suites (suite.h) and sweeps (ci/sweep/) write
// it, and its run: render (cached by content), track, score, metrics.

#include <filesystem>
#include <map>
#include <mutex>
#include <string>
#include <vector>

#include "common/json_reader.h"
#include "sim/sequence/render_job.h"
#include "tracker/pipeline/track_settings.h"

namespace irbench {

struct Scenario {
  std::string name;
  std::string file;  // the file that lists it (a suite, one it includes, a sweep spec)
  RenderJobOptions render;
  bool optional = false;    // skipped, with a warning, when its motion file is absent
  std::string missing;      // why it is skipped; empty: it runs
  TrackerSettings tracker;  // the scenario's `track` object: keys of TrackSettings()
};

// The keys ReadScenarioKeys reads: scene, rig, avatar, motion, optional,
// max_seconds, sensor, seed, frames, background_frames,
// background_screen_sweep, track.
const std::vector<std::string>& ScenarioKeys();

// Reads ScenarioKeys() of `s` (it does not check for other keys: the caller
// knows its own) into `sc`; a motion file or a `track` path relative to
// `file`'s folder. Throws InputError naming the file and field.
void ReadScenarioKeys(const JsonNode& s, const std::filesystem::path& file, Scenario* sc);

// The metrics a scenario measures (see suite.h for each one's meaning).
const std::vector<std::string>& KnownMetrics();
std::string KnownMetricsText();  // comma-separated, for error messages
// True for metrics where higher is better (fractions, IoU, accuracies).
bool HigherIsBetter(const std::string& metric);

// The files a scenario's render reads (validated, names resolved).
std::vector<std::filesystem::path> ScenarioInputFiles(const RenderJobOptions& render);

// The render inputs that decide the frames, hashed (16 hex digits) with the
// tool version and the contents of the files they name. A file given by its
// path counts by its file name and contents, not its folder: the same clip
// or rig beside another checkout, or in another sweep's folder, hits the same
// cache.
std::string CacheKey(const RenderJobOptions& render);

// What one scenario measured: its metrics and, for pooling over scenarios,
// how many samples each metric is a mean over.
struct Measured {
  std::map<std::string, double> metrics;
  std::map<std::string, double> weights;
  std::string group;  // "library" or "mocap" (the motion's kind)
  std::string person;
};

// Renders the scenario into <cache>/<name>-<CacheKey> unless that holds a
// finished render already (one render at a time under `render_mutex`: a
// render job owns the process's GL display), tracks and scores it there, and
// returns its metrics; `report` gets the score's report.html. `label` starts
// the log lines ("suite smoke").
Measured RunScenario(const Scenario& sc, const std::string& label, const std::filesystem::path& cache,
                     std::mutex* render_mutex, std::filesystem::path* report);

}  // namespace irbench
