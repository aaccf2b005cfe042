// `irbench render`: a calibrated multi-camera sequence with exact truth.

#include <filesystem>
#include <iostream>
#include <memory>
#include <string>

#include "cli/commands.h"
#include "cli/option_checks.h"
#include "cli/render_options.h"
#include "sim/sequence/render_job.h"

namespace irbench::cli {
namespace {

// What `irbench render`'s flags bind to.
struct RenderArgs {
  RenderJobOptions job;
  std::string backend = "auto";
  std::string shadows;
  int frames = 0;
  bool no_sweep = false;
  std::string out;
};

// Renders the sequence; prints its folder.
int RunRender(const CLI::App& cmd, RenderArgs& args) {
  RenderJobOptions& render = args.job;
  if (cmd.count("--frames") > 0) render.frames = args.frames;
  RequireNotEmpty(cmd, "--out", args.out);
  render.out = args.out;
  render.screen_sweep = !args.no_sweep;
  render.backend = BackendOrThrow(args.backend);
  ApplyShadows(args.shadows, render);
  const std::filesystem::path folder = RunRenderJob(render);
  std::cout << folder.string() << "\n";
  return kExitOk;
}

}  // namespace

std::vector<Command> AddRenderCommand(CLI::App& app) {
  auto args = std::make_shared<RenderArgs>();
  CLI::App* cmd = app.add_subcommand(
      "render", "Render a calibrated multi-camera sequence with exact truth into a folder");
  AddRenderInputOptions(cmd, args->job, args->backend, args->shadows);
  cmd->add_option("--frames", args->frames, "frames to render (default: the motion's length)")
      ->transform(IntegerIn(1, 1000000));
  cmd->add_option("--background-frames", args->job.background_frames,
                  "empty-stage frames per camera")
      ->capture_default_str()
      ->transform(IntegerIn(0, 10000));
  cmd->add_flag(
      "--no-screen-sweep", args->no_sweep,
      "film the empty stage with the screens playing their content; by default they show a "
      "brightness ramp (0.25 to 1.75 of the content's level) so the tracker can tell their light "
      "from the illuminators'");
  cmd->add_option("--seed", args->job.seed, "seed for everything random")
      ->capture_default_str()
      ->transform(Uint64Text());
  cmd->add_option("--out", args->out,
                  "output folder (default: renders/<rig>-<avatar>-<motion>-s<seed>)");
  cmd->add_flag("--force", args->job.overwrite,
                "replace an existing output folder (only one irbench wrote)");
  cmd->add_flag("--resume", args->job.resume,
                "carry on from the frames an interrupted render of the same --out with the same\n"
                "options left behind (its hidden .NAME.partial-PID folder); the result is the\n"
                "same, byte for byte, as an uninterrupted render");
  cmd->add_flag("--depth", args->job.write_depth, "also write camera depth as OpenEXR");
  cmd->add_flag("--video", args->job.write_video,
                "also write each camera's frames and empty-stage frames as a lossless video "
                "(videos/<cam>.mkv, background/<cam>.mkv: FFV1), trackable with irbench track --from-videos");
  return {{cmd, [cmd, args] { return RunRender(*cmd, *args); }}};
}

}  // namespace irbench::cli
