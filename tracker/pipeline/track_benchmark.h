#pragma once
// `irbench bench track`'s measurement: times the tracker's stages per
// frame-set on a sequence that already exists (images preloaded, so disk and
// PNG decoding are not counted). Rendering the sequence is the caller's part
// (cli/bench_command.cc): the tracker's libraries do not depend on sim/.

#include <filesystem>
#include <string>
#include <vector>

namespace irbench {

struct TrackBenchRow {
  std::string stage;
  double median_ms = 0;  // per frame-set, all cameras
  double mean_ms = 0;
};

// Times, per frame-set, the front end's stages over `repeats` passes (with
// OpenCV's threads and on one), then the pose tracker (thesis 6.3) at 25 to
// 400 particles on the same features. `sequence` is a folder written by
// render, with empty-stage frames. Sets *cameras to its camera count.
std::vector<TrackBenchRow> RunTrackBenchmark(const std::filesystem::path& sequence,
                                             int repeats,
                                             int* cameras);

}  // namespace irbench
