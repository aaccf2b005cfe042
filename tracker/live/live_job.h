#pragma once
// `irbench live`: the tracker frame by frame as frame-sets arrive, each
// tracked one published over UDP as an OSC bundle (osc_publisher.h,
// docs/live.md). Frame-sets arrive at the source's fps (or --fps) from a
// sequence's frame files or a recording's videos (sequence_input.h), or as
// a live rig's cameras deliver them (capture_input.h); one
// that arrives while the tracker is still busy replaces the one waiting,
// which is dropped and counted: nothing queues without bound.

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "tracker/io/capture_input.h"
#include "tracker/io/sequence_input.h"
#include "tracker/live/osc_publisher.h"
#include "tracker/pipeline/track_settings.h"

namespace irbench {

struct LiveJobOptions {
  // A sequence folder or a recording; with `capture`, the live rig's folder
  // (its calibration, screens, and optionally background videos).
  std::filesystem::path source;
  SequenceInputOptions input;
  // Capture devices, one per camera of the rig's calibration: frame-sets are
  // read as the devices deliver them, from the start until they end, a
  // signal stops the run, or `frames` have been tracked. The empty stage is
  // `input.empty_stage_s` of the capture (frame-sets counted at the rig's
  // fps; not tracked), or the folder's background/<cam>.<ext> videos.
  std::vector<CaptureSource> capture;
  TrackerSettings tracker;
  OscTarget osc{"127.0.0.1", 9000};
  // Arrival rate; default: the source's. With `capture`, the most frame-sets
  // read per second (a device paces itself; a file or an unpaced stream is
  // paced by this), and the rig's fps where neither calib/cameras.json nor
  // the first device gives one.
  std::optional<double> fps;
  std::filesystem::path record;  // also write the tracked lines as track.jsonl here
  bool overwrite = false;        // replace an existing record file
  std::optional<int> frames;     // default: all (with `capture`: after the empty stage)
};

struct LiveReport {
  int arrived = 0, tracked = 0, dropped = 0;
  // With a capture: the empty stage's frame-sets (its frames come first and
  // are not tracked), and whether a signal (SIGINT, SIGTERM) ended the run,
  // which for a capture is the normal way to stop: the record is written.
  int empty_stage = 0;
  bool stopped_by_signal = false;
  int send_failures = 0;
  double fps = 0;
  // From a frame-set's arrival (read and in memory) to its bundle sent, ms.
  double latency_median_ms = 0, latency_p99_ms = 0, latency_max_ms = 0;
};

// Throws InputError on bad options or input (before anything is sent);
// Cancelled on a signal, except while capturing (above).
LiveReport RunLiveJob(const LiveJobOptions& options);

}  // namespace irbench
