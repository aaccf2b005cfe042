#pragma once
// `irbench suite run`: closed-loop accuracy regression (issue 8). A suite file
// (ci/suites/<name>.json, irbench.suite/1) lists scenarios — scene, rig,
// person, motion, sensor preset, seed, frames, tracker options — with
// per-metric thresholds. Each scenario is rendered (cached by a hash of its
// render inputs and the tool version, under renders/cache/), tracked and
// scored; its metrics are checked against the thresholds and against the
// blessed baseline (ci/baselines/<name>.json) within the metric's tolerance.
// `--bless` writes the baseline from this run on purpose. Each scenario's
// score, tables and report.html are written beside its track in the cache.
//
// Scenarios run in parallel, up to `jobs` at a time (default: the core
// count): renders one at a time (a render job owns the process's GL display),
// tracking and scoring side by side. Each scenario has its own cache folder,
// so results do not depend on the order or the number of workers.
//
// Metrics (all from the tracker's output against the truth):
//   silhouette_iou_median   median over camera-frames of the silhouettes' IoU
//                           with the truth masks (higher is better)
//   tracked_fraction        frames tracked / frames with the person on stage
//   <joint>_mean_cm         a Table 6.1 joint's mean error, Chauvenet outliers
//                           removed (root, waist, neck, left_/right_shoulder,
//                           _elbow, _wrist)
//   arms_mean_cm            the mean of the six arm joints' means
//   pointing_mean_deg       pointing error, both hands' kept samples (Table 6.3)
//   rest_accuracy           rest-state agreement, both arms (0..1)
//   posture_accuracy        recognised atom pairs equal to the truth's (0..1;
//                           when the tracker has posture atoms)
//   gesture_identification  performances identified (0..1; when the tracker
//                           has gesture models and the motion has gestures)
//   motion_mean_recall      motion labels: the mean over truth labels of each
//                           label's recall, both arms (0..1; thesis 7.2; when
//                           the tracker has a motion-label model)

#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace irbench {

struct SuiteRunOptions {
  std::filesystem::path suite;      // file or name in ci/suites/
  std::filesystem::path baselines;  // default: <data root>/ci/baselines
  std::filesystem::path cache;      // default: <data root>/renders/cache
  bool bless = false;
  int jobs = 0;  // scenarios at a time; 0: the core count
};

struct MetricResult {
  std::string scenario, metric;
  double value = 0;
  std::string bound;     // "max 15" / "min 0.7" / ""
  std::string baseline;  // "12.1 ± 1.2" / "none"
  bool pass = true;
  std::string why;  // when it fails
};

// A suite's figures pooled over scenarios of one kind of motion ("library":
// the motion library, keyframes, sessions; "mocap": BVH/AMC clips) and one
// person, or all persons ("all"): every metric the mean over all samples of
// those scenarios, arms the mean of the six pooled arm joints (cm; rest and
// tracked as fractions).
struct PooledRow {
  std::string group, person;
  int scenarios = 0;
  int frames = 0;  // frames with the person on the stage
  std::map<std::string, double> metrics;
};

struct SuiteResult {
  std::string name;
  std::vector<MetricResult> rows;
  std::vector<std::pair<std::string, std::filesystem::path>> reports;  // scenario -> its report.html
  std::vector<std::pair<std::string, std::string>> skipped;          // scenario -> why (optional, data absent)
  std::vector<PooledRow> pooled;
  std::filesystem::path summary;  // the folder with summary.md and report.html (<cache>/suite-<name>)
  bool pass = true;
  std::string Table() const;        // Markdown: every scenario's metrics against thresholds and baseline
  std::string PooledTable() const;  // Markdown: the pooled rows
};

// Throws InputError for a bad suite file (naming the file and field).
SuiteResult RunSuite(const SuiteRunOptions& options);

}  // namespace irbench
