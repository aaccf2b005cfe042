// `irbench live`: the tracker as frame-sets arrive, published over OSC
// (tracker/live/live_job.h, docs/live.md).

#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "cli/commands.h"
#include "cli/option_checks.h"
#include "cli/tracker_options.h"
#include "common/error.h"
#include "tracker/live/live_job.h"

namespace irbench::cli {
namespace {

struct LiveArgs {
  LiveJobOptions job;
  std::string source, osc = "127.0.0.1:9000", record, empty_stage;
  std::vector<std::string> capture;
  double fps = 0;
  int frames = 0;
  TypedTrackerSettings settings;
};

int RunLive(const CLI::App& cmd, LiveArgs& args) {
  LiveJobOptions& live = args.job;
  live.source = args.source;
  args.settings.ApplyTo(live.tracker);
  live.osc = ParseOscTarget(args.osc, "--osc");
  RequireNotEmpty(cmd, "--record", args.record);
  live.record = args.record;
  if (cmd.count("--fps") > 0) live.fps = args.fps;
  if (cmd.count("--frames") > 0) live.frames = args.frames;
  if (!args.empty_stage.empty()) live.input.empty_stage_s = ParseEmptyStage(args.empty_stage);
  for (const std::string& text : args.capture) live.capture.push_back(ParseCaptureSource(text));
  const LiveReport r = RunLiveJob(live);
  if (!live.capture.empty() && r.empty_stage > 0) {
    std::printf("live: the empty stage: %d frame-sets captured\n", r.empty_stage);
  }
  if (r.stopped_by_signal) std::printf("live: stopped by a signal; what was tracked is published and recorded\n");
  std::printf(
      "live: %d frame-sets arrived at %.1f/s; %d tracked and published, %d dropped while the tracker was busy\n"
      "latency from arrival to OSC bundle: median %.1f ms, 99th percentile %.1f ms, max %.1f ms%s\n",
      r.arrived, r.fps, r.tracked, r.dropped, r.latency_median_ms, r.latency_p99_ms, r.latency_max_ms,
      r.send_failures > 0 ? (", " + std::to_string(r.send_failures) + " sends failed").c_str() : "");
  return kExitOk;
}

}  // namespace

std::vector<Command> AddLiveCommand(CLI::App& app) {
  auto args = std::make_shared<LiveArgs>();
  CLI::App* cmd = app.add_subcommand(
      "live",
      "Track frame-sets as they arrive and publish each over UDP as an OSC bundle (docs/live.md):\n"
      "joints, pointing rays and screen hits, rest state. Frame-sets arrive at the source's fps from a\n"
      "sequence folder or a recording's videos; one that arrives while the tracker is busy replaces the\n"
      "waiting one, which is dropped and counted. Prints the latency from arrival to message.\n"
      "With --capture, frame-sets come from a live rig's cameras (one device per calibrated camera) until\n"
      "the devices end, --frames are tracked, or Ctrl-C; the empty stage is captured first (--empty-stage).\n"
      "  irbench live renders/demo --osc 127.0.0.1:9000 --record live.jsonl\n"
      "  irbench live my_rig --capture left=/dev/video0 --capture right=/dev/video2 --empty-stage 1:3");
  cmd->add_option("SOURCE", args->source,
                  "sequence folder or recording (docs/recordings.md); with --capture, the rig's folder (calibration)")
      ->required();
  AddTrackerSettingOptions(cmd, args->settings);
  cmd->add_option("--osc", args->osc, "where to send: HOST:PORT (UDP)")->capture_default_str();
  cmd->add_option("--fps", args->fps, "arrival rate, frame-sets per second (default: the source's)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--frames", args->frames, "frame-sets to play (default: all; with --capture, after the empty stage)")->transform(IntegerIn(1, 1000000));
  cmd->add_option("--record", args->record, "also write the published lines as a track.jsonl file");
  cmd->add_flag("--force", args->job.overwrite, "replace an existing --record file");
  cmd->add_flag("--from-videos", args->job.input.videos, "read SOURCE's videos/ even where its frames/ exist");
  cmd->add_option("--empty-stage", args->empty_stage,
                  "FROM:TO seconds of the videos (or of the capture) that show the empty stage (no background videos)");
  cmd->add_option("--capture", args->capture,
                  "CAMERA=DEVICE, once per calibrated camera: a device index (0), a device (/dev/video2), a stream's\n"
                  "URL or anything else OpenCV's VideoCapture opens (docs/live.md)")
      ->allow_extra_args(false);
  return {{cmd, [cmd, args] { return RunLive(*cmd, *args); }}};
}

}  // namespace irbench::cli
