// `irbench track`: the tracker over a sequence folder.

#include <iostream>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "cli/commands.h"
#include "cli/option_checks.h"
#include "cli/tracker_options.h"
#include "common/error.h"
#include "tracker/pipeline/track_job.h"

namespace irbench::cli {
namespace {

// What `irbench track`'s flags bind to.
struct TrackArgs {
  TrackJobOptions job;
  std::string sequence, out, empty_stage;
  int frames = 0;
  TypedTrackerSettings settings;
};

// Runs the track job; prints its output folder.
int RunTrack(const CLI::App& cmd, TrackArgs& args) {
  TrackJobOptions& track = args.job;
  track.sequence = args.sequence;
  RequireNotEmpty(cmd, "--out", args.out);
  track.out = args.out;
  args.settings.ApplyTo(track.tracker);
  if (cmd.count("--frames") > 0) track.frames = args.frames;
  if (!args.empty_stage.empty()) track.input.empty_stage_s = ParseEmptyStage(args.empty_stage);
  std::cout << RunTrackJob(track).string() << "\n";
  return kExitOk;
}

}  // namespace

std::vector<Command> AddTrackCommand(CLI::App& app) {
  auto args = std::make_shared<TrackArgs>();
  CLI::App* cmd = app.add_subcommand(
      "track",
      "Run the tracker on a sequence folder (frames, calibration and empty-stage frames only)");
  cmd->add_option("SEQ", args->sequence,
                  "sequence folder written by render, or a recording: videos/<cam>.<ext>, EasyMocap "
                  "intri.yml and extri.yml, background/<cam>.<ext> (docs/recordings.md)")
      ->required();
  cmd->add_flag("--from-videos", args->job.input.videos,
                "read SEQ's videos/ (irbench render --video) even where its frames/ exist");
  cmd->add_option("--empty-stage", args->empty_stage,
                  "FROM:TO seconds of the videos that show the empty stage, when there are no "
                  "background/<cam> videos");
  AddTrackerSettingOptions(cmd, args->settings);
  cmd->add_flag("--overlays", args->job.overlays, "also write debug overlays (PNG, colour)");
  cmd->add_flag("--ply", args->job.ply,
                "also write the voxel and polyhedral hulls per frame as PLY");
  cmd->add_flag("--descriptors", args->job.descriptors,
                "also write every frame's shape descriptor (thesis 4.3) to descriptors.npy (float32, "
                "frames x 13824 bins r-theta-phi; zeros where the stage looks empty)");
  cmd->add_option("--frames", args->frames, "frames to process (default: all)")
      ->transform(IntegerIn(1, 1000000));
  cmd->add_option("--out", args->out, "output folder (default: SEQ/track)");
  cmd->add_flag("--force", args->job.overwrite,
                "replace an existing output folder (only one irbench wrote)");
  return {{cmd, [cmd, args] { return RunTrack(*cmd, *args); }}};
}

}  // namespace irbench::cli
