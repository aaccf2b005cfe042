// `irbench score`: a track file against the sequence's truth.

#include <filesystem>
#include <iostream>
#include <memory>
#include <string>

#include "ci/score/score_job.h"
#include "cli/commands.h"
#include "cli/option_checks.h"

namespace irbench::cli {
namespace {

// What `irbench score`'s flags bind to.
struct ScoreArgs {
  ScoreJobOptions job;
  std::string sequence, track, out;
  bool no_report = false;
};

// Runs the score job; prints the tables, the report and the output folder.
int RunScore(const CLI::App& cmd, ScoreArgs& args) {
  ScoreJobOptions& score = args.job;
  RequireNotEmpty(cmd, "--out", args.out);
  RequireNotEmpty(cmd, "--track", args.track);
  score.sequence = args.sequence;
  score.track = args.track;
  score.out = args.out;
  score.report = !args.no_report;
  std::string tables;
  const std::filesystem::path folder = RunScoreJob(score, &tables);
  std::cout << tables << "\n";
  if (score.report) std::cout << "report  " << (folder / "report.html").string() << "\n";
  std::cout << folder.string() << "\n";
  return kExitOk;
}

}  // namespace

std::vector<Command> AddScoreCommand(CLI::App& app) {
  auto args = std::make_shared<ScoreArgs>();
  CLI::App* cmd = app.add_subcommand(
      "score",
      "Score a track file against the sequence's truth: the thesis's tables (joint errors with\n"
      "Chauvenet outliers, pointing angles, rest state, motion labels; the silhouettes' IoU per "
      "camera\n"
      "when irbench track's silhouettes/ lie beside the track file) as JSON, Markdown and CSV, "
      "and\n"
      "report.html: the tables, plots and a frame viewer with the truth and the track drawn over\n"
      "every camera's image, worst frames first");
  cmd->add_option("SEQ", args->sequence, "sequence folder written by render")->required();
  cmd->add_option("--track", args->track, "track.jsonl to score (default: SEQ/track/track.jsonl)");
  cmd->add_option("--out", args->out, "output folder (default: SEQ/score)");
  cmd->add_flag("--include-rest-arms", args->job.score.include_rest_arms,
                "also score elbows and wrists of arms at rest (the thesis leaves them out)");
  cmd->add_flag("--force", args->job.overwrite,
                "replace an existing output folder (only one irbench wrote)");
  cmd->add_flag(
      "--no-report", args->no_report,
      "skip report.html (tables, gnuplot plots, frame viewer; opens offline in a browser)");
  return {{cmd, [cmd, args] { return RunScore(*cmd, *args); }}};
}

}  // namespace irbench::cli
