// `irbench sweep run|run-one|submit|collect`: stress sweeps over camera
// placements and scenario values, here or on a Slurm cluster.

#include <filesystem>
#include <iostream>
#include <memory>
#include <string>

#include "ci/sweep/sweep.h"
#include "common/paths.h"
#include "cli/commands.h"
#include "cli/option_checks.h"

namespace irbench::cli {
namespace {

// What the sweep subcommands' flags bind to.
struct SweepArgs {
  SweepOptions job;
  std::string spec, out, cache;
  int index = 0;
  SlurmOptions slurm;
  std::string irbench, sbatch;
  bool no_submit = false;
};

void Bind(const CLI::App& cmd, SweepArgs& args) {
  RequireNotEmpty(cmd, "--out", args.out);
  RequireNotEmpty(cmd, "--cache", args.cache);
  // A file, or a name in ci/sweeps/ (`side_camera`).
  args.job.spec = std::filesystem::is_regular_file(args.spec) ? std::filesystem::path(args.spec)
                                                             : ResolveDataFile("ci/sweeps", args.spec, "SPEC");
  args.job.out = args.out;
  args.job.cache = args.cache;
}

void AddCommon(CLI::App* cmd, SweepArgs& args) {
  cmd->add_option("SPEC", args.spec, "sweep spec: a file (irbench.sweep/1; docs/sweeps.md) or a name in ci/sweeps/")
      ->required();
  cmd->add_option("--out", args.out, "sweep folder: points, rigs, tables, report (default: renders/sweeps/<name>)");
  cmd->add_option("--cache", args.cache, "render cache folder, seen by every node (default: renders/cache)");
}

void PrintCollected(const SweepCollected& c) {
  std::cout << c.done << " of " << c.total << " points done";
  if (c.best) std::cout << "; best " << PointName(*c.best);
  std::cout << "\n  " << c.md.string() << "\n  " << c.csv.string() << "\n  " << c.html.string() << "\n";
  if (!c.suite.empty()) std::cout << "  " << c.suite.string() << " (the hardest points as a suite)\n";
}

int RunCommand(const CLI::App& cmd, SweepArgs& args) {
  Bind(cmd, args);
  const SweepRun run = RunSweep(args.job);
  const SweepCollected c = CollectSweep(args.job);
  PrintCollected(c);
  for (const auto& [index, why] : run.failed) std::cerr << "error: point " << PointName(index) << ": " << why << "\n";
  return run.failed.empty() ? kExitOk : kExitRuntime;
}

int RunOneCommand(const CLI::App& cmd, SweepArgs& args) {
  Bind(cmd, args);
  const SweepRun run = RunSweep(args.job, args.index);
  for (const auto& [index, why] : run.failed) std::cerr << "error: point " << PointName(index) << ": " << why << "\n";
  return run.failed.empty() ? kExitOk : kExitRuntime;
}

int SubmitCommand(const CLI::App& cmd, SweepArgs& args) {
  Bind(cmd, args);
  args.slurm.irbench = args.irbench;
  args.slurm.sbatch = args.sbatch;
  args.slurm.submit = !args.no_submit;
  const SlurmSubmission s = SubmitSweep(args.job, args.slurm);
  if (s.indices.empty()) {
    std::cout << "every point is done: nothing to submit; `irbench sweep collect` writes the tables\n";
    return kExitOk;
  }
  std::cout << s.indices.size() << " point(s) in";
  for (const auto& script : s.scripts) std::cout << " " << script.string();
  std::cout << "\n";
  for (const std::string& id : s.job_ids) std::cout << "submitted: job " << id << "\n";
  return kExitOk;
}

int CollectCommand(const CLI::App& cmd, SweepArgs& args) {
  Bind(cmd, args);
  const SweepCollected c = CollectSweep(args.job);
  PrintCollected(c);
  if (!c.missing.empty()) {
    std::cerr << "error: " << c.missing.size() << " point(s) not done yet (first " << PointName(c.missing.front())
              << "); run or submit again\n";
    return kExitRuntime;
  }
  return kExitOk;
}

}  // namespace

std::vector<Command> AddSweepCommand(CLI::App& app) {
  auto args = std::make_shared<SweepArgs>();
  CLI::App* sweep = app.add_subcommand(
      "sweep", "Stress sweeps: camera placements and scenario values, here or on a Slurm cluster");
  sweep->require_subcommand(1);
  CLI::App* run = sweep->add_subcommand(
      "run", "Run every point not done yet (render cached, track, score), then collect the tables and report");
  AddCommon(run, *args);
  run->add_option("--jobs", args->job.jobs, "points at a time (default: the core count)")->transform(IntegerIn(1, 256));
  CLI::App* one = sweep->add_subcommand("run-one", "Run one point (what each Slurm array task runs)");
  AddCommon(one, *args);
  one->add_option("INDEX", args->index, "the point, 0 .. points-1")->required()->transform(IntegerIn(0, 999999));
  CLI::App* submit = sweep->add_subcommand(
      "submit", "Write an sbatch job array over the points not done yet and submit it to Slurm");
  AddCommon(submit, *args);
  submit->add_option("--sbatch-option", args->slurm.sbatch_lines,
                     "an extra #SBATCH line, e.g. --sbatch-option=--partition=debug (repeatable)");
  submit->add_option("--max-parallel", args->slurm.max_parallel, "array tasks running at once (default: no limit)")
      ->transform(IntegerIn(1, 100000));
  submit->add_option("--irbench", args->irbench, "the irbench the tasks run (default: this one)");
  submit->add_option("--sbatch", args->sbatch, "the sbatch to call (default: $IRBENCH_SBATCH or sbatch on PATH)");
  submit->add_flag("--no-submit", args->no_submit, "only write the script");
  CLI::App* collect = sweep->add_subcommand(
      "collect", "Merge the finished points into sweep.csv, sweep.md and report.html; exit 1 while points are missing");
  AddCommon(collect, *args);
  return {{run, [run, args] { return RunCommand(*run, *args); }},
          {one, [one, args] { return RunOneCommand(*one, *args); }},
          {submit, [submit, args] { return SubmitCommand(*submit, *args); }},
          {collect, [collect, args] { return CollectCommand(*collect, *args); }}};
}

}  // namespace irbench::cli
