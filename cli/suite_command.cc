// `irbench suite run`: the closed-loop accuracy regression over a suite of scenarios.

#include <iostream>
#include <memory>
#include <string>

#include "ci/suite_runner/suite.h"
#include "cli/commands.h"
#include "cli/option_checks.h"

namespace irbench::cli {
namespace {

// What `irbench suite run`'s flags bind to.
struct SuiteArgs {
  SuiteRunOptions job;
  std::string name, baselines, cache;
};

// Runs the suite; prints its table and reports; exit 1 when a metric failed.
int RunSuiteCommand(const CLI::App& cmd, SuiteArgs& args) {
  SuiteRunOptions& suite = args.job;
  RequireNotEmpty(cmd, "--baselines", args.baselines);
  RequireNotEmpty(cmd, "--cache", args.cache);
  suite.suite = args.name;
  suite.baselines = args.baselines;
  suite.cache = args.cache;
  const SuiteResult r = RunSuite(suite);
  std::cout << "# suite " << r.name << (suite.bless ? " (blessed)" : "") << "\n"
            << r.Table() << "\n## pooled (cm; all samples of the scenarios in a row)\n"
            << r.PooledTable() << "\nreports:\n";
  for (const auto& [scenario, report] : r.reports)
    std::cout << "  " << scenario << "  " << report.string() << "\n";
  std::cout << "summary: " << (r.summary / "report.html").string() << "\n";
  if (!r.skipped.empty()) {
    std::cout << "\nskipped (optional, data absent):\n";
    for (const auto& [scenario, why] : r.skipped) std::cout << "  " << scenario << "  " << why << "\n";
  }
  if (!r.pass) {
    int failed = 0;
    for (const auto& row : r.rows) failed += !row.pass;
    std::cerr << "error: suite " << r.name << ": " << failed << " metric(s) failed\n";
    return kExitRuntime;
  }
  return kExitOk;
}

}  // namespace

std::vector<Command> AddSuiteCommand(CLI::App& app) {
  auto args = std::make_shared<SuiteArgs>();
  CLI::App* suite_cmd =
      app.add_subcommand("suite", "Closed-loop accuracy regression: run a suite of scenarios");
  suite_cmd->require_subcommand(1);
  CLI::App* run = suite_cmd->add_subcommand(
      "run",
      "Render (cached), track and score every scenario of a suite; check thresholds and the\n"
      "blessed baseline; print a pass/fail table; exit 1 on a regression");
  run->add_option("SUITE", args->name, "suite name (ci/suites/) or file")->required();
  run->add_flag("--bless", args->job.bless,
                "write this run's figures as the new baseline (on purpose)");
  run->add_option("--baselines", args->baselines, "baseline folder (default: ci/baselines)");
  run->add_option("--cache", args->cache, "render cache folder (default: renders/cache)");
  run->add_option("--jobs", args->job.jobs, "scenarios at a time (default: the core count)")
      ->transform(IntegerIn(1, 256));
  return {{run, [run, args] { return RunSuiteCommand(*run, *args); }}};
}

}  // namespace irbench::cli
