#pragma once
// `irbench live`: the tracker frame by frame as frame-sets arrive, each
// tracked one published over UDP as an OSC bundle (osc_publisher.h,
// docs/live.md). Frame-sets arrive at the source's fps (or --fps) from a
// sequence's frame files or a recording's videos (sequence_input.h); one
// that arrives while the tracker is still busy replaces the one waiting,
// which is dropped and counted: nothing queues without bound.

#include <filesystem>
#include <optional>
#include <string>

#include "tracker/io/sequence_input.h"
#include "tracker/live/osc_publisher.h"
#include "tracker/pipeline/track_settings.h"

namespace irbench {

struct LiveJobOptions {
  std::filesystem::path source;  // a sequence folder or a recording
  SequenceInputOptions input;
  TrackerSettings tracker;
  OscTarget osc{"127.0.0.1", 9000};
  std::optional<double> fps;     // arrival rate; default: the source's
  std::filesystem::path record;  // also write the tracked lines as track.jsonl here
  bool overwrite = false;        // replace an existing record file
  std::optional<int> frames;     // default: all
};

struct LiveReport {
  int arrived = 0, tracked = 0, dropped = 0;
  int send_failures = 0;
  double fps = 0;
  // From a frame-set's arrival (read and in memory) to its bundle sent, ms.
  double latency_median_ms = 0, latency_p99_ms = 0, latency_max_ms = 0;
};

// Throws InputError on bad options or input (before anything is sent).
LiveReport RunLiveJob(const LiveJobOptions& options);

}  // namespace irbench
