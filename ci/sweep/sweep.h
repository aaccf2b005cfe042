#pragma once
// `irbench sweep`: many render-track-score points from one spec
// (sweep_spec.h), on this machine (`run`, `--jobs N`) or as a Slurm job array
// (`submit` writes and submits an sbatch script whose tasks each run
// `irbench sweep run-one SPEC INDEX`; `collect` merges). Each point writes
// OUT/points/pNNNN.json when it finishes — its coordinates and metrics, no
// times or paths, so the same point gives the same bytes on any executor —
// and a finished point is never run again: a killed or failed task is simply
// submitted again. Renders are cached by content in the cache folder (the
// suites' renders/cache by default), which every node must see.
//
// OUT holds spec.json (the spec the points belong to: another spec with the
// same OUT is refused), points/, rigs/ (a placement point's rig, which renders
// that point alone), and after `collect` sweep.csv, sweep.md and report.html.

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "ci/sweep/sweep_spec.h"

namespace irbench {

struct SweepOptions {
  std::filesystem::path spec;   // the spec file
  std::filesystem::path out;    // default: renders/sweeps/<name>
  std::filesystem::path cache;  // default: renders/cache
  int jobs = 0;                 // points at a time (`run`); 0: the core count
};

// The spec loaded and OUT and the cache resolved and checked (OUT/spec.json
// written, or compared with this spec).
struct SweepContext {
  SweepSpec spec;
  std::filesystem::path out, cache;
};
SweepContext OpenSweep(const SweepOptions& options);

std::filesystem::path PointFile(const SweepContext& sweep, int index);
// The spec's metric of each finished point, read from its point file.
PointMetric PointMetrics(const SweepContext& sweep);
// The indices without a point file yet, ascending.
std::vector<int> MissingPoints(const SweepContext& sweep);

struct SweepRun {
  int total = 0;        // points in the spec
  int done_before = 0;  // finished by an earlier run
  int ran = 0;          // finished now
  std::vector<std::pair<int, std::string>> failed;  // index -> why
};

// Runs the points without a point file, `jobs` at a time (renders one at a
// time, tracking and scoring side by side), a search's generations one after
// another; a failing point is logged and the others of its generation go on
// (a search stops after that generation). With `only`, runs that point alone
// (when not done).
SweepRun RunSweep(const SweepOptions& options, std::optional<int> only = std::nullopt);

struct SweepCollected {
  int total = 0, done = 0;
  std::vector<int> missing;
  std::optional<int> best;  // the best point by the spec's metric
  std::filesystem::path csv, md, html;
  std::filesystem::path suite;  // adversarial: OUT/suite.json, the 5 hardest points as a suite
};

// Writes OUT/sweep.csv (a row per finished point: index, coordinates, every
// metric), OUT/sweep.md (points ranked by the spec's metric, the metric per
// value of each axis) and OUT/report.html (the same with placement heat maps
// and links to each point's report.html); an adversarial sweep also
// OUT/suite.json, its 5 hardest points as a suite (`irbench suite run`).
SweepCollected CollectSweep(const SweepOptions& options);

struct SlurmOptions {
  std::vector<std::string> sbatch_lines;  // extra `#SBATCH` options ("--partition=debug")
  std::filesystem::path irbench;          // the program the tasks run; default: this one
  std::filesystem::path sbatch;           // default: $IRBENCH_SBATCH, else `sbatch` on PATH
  bool submit = true;                     // false: only write the script
  int max_parallel = 0;                   // array throttle (%N); 0: none
};

struct SlurmSubmission {
  std::vector<std::filesystem::path> scripts;  // one per generation with points not done
  std::vector<int> indices;                     // the points not done
  std::vector<std::string> job_ids;             // empty when not submitted (nothing missing, or submit = false)
};

// Writes OUT/slurm/sweep-<k>.sbatch, a job array over the missing points,
// each task `irbench sweep run-one SPEC $SLURM_ARRAY_TASK_ID --out OUT
// --cache CACHE` with its log in OUT/slurm/, and submits it with sbatch. A
// search gets one array per generation with missing points, each submitted
// to start after the one before has ended (--dependency=afterany).
SlurmSubmission SubmitSweep(const SweepOptions& options, const SlurmOptions& slurm);

}  // namespace irbench
