// `irbench demo`: render the default session, track it, score it.

#include <iostream>
#include <memory>
#include <string>

#include "ci/demo/demo_job.h"
#include "cli/commands.h"
#include "cli/option_checks.h"

namespace irbench::cli {
namespace {

// What `irbench demo`'s flags bind to.
struct DemoArgs {
  DemoOptions job;
  std::string out;
  int frames = 0;
};

// Runs the demo; prints the tables and where each part went.
int RunDemoCommand(const CLI::App& cmd, DemoArgs& args) {
  DemoOptions& demo = args.job;
  RequireNotEmpty(cmd, "--out", args.out);
  demo.out = args.out;
  if (cmd.count("--frames") > 0) demo.frames = args.frames;
  const DemoResult r = RunDemo(demo);
  std::cout << r.tables << "\n"
            << "sequence  " << r.sequence.string() << "\n"
            << "track     " << r.track.string() << "\n"
            << "score     " << r.score.string() << "\n"
            << "report    " << (r.score / "report.html").string() << "  (open in a browser)\n";
  return kExitOk;
}

}  // namespace

std::vector<Command> AddDemoCommand(CLI::App& app) {
  auto args = std::make_shared<DemoArgs>();
  DemoOptions& demo = args->job;
  CLI::App* cmd = app.add_subcommand(
      "demo",
      "The main job: render the default session (theater4, thesis preset, about 20 s),\n"
      "run the tracker, score it against the truth, print the tables and write report.html");
  cmd->add_option("--out", args->out,
                  "sequence folder, track/ and score/ go inside (default: renders/demo)");
  cmd->add_option("--avatar", demo.avatar, "avatar name (avatars/) or file")->capture_default_str();
  cmd->add_option("--motion", demo.motion, "motion, as for render --motion")->capture_default_str();
  cmd->add_option("--sensor", demo.sensor, "sensor preset: clean, thesis or harsh")
      ->capture_default_str();
  cmd->add_option("--frames", args->frames,
                  "frames to render (default: the whole session; fewer for a quick look)")
      ->transform(IntegerIn(1, 1000000));
  cmd->add_option("--seed", demo.seed, "seed for everything random")
      ->capture_default_str()
      ->transform(Uint64Text());
  cmd->add_flag("--force", demo.overwrite, "replace an existing output folder (only one irbench wrote)");
  return {{cmd, [cmd, args] { return RunDemoCommand(*cmd, *args); }}};
}

}  // namespace irbench::cli
