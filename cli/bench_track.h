#pragma once
// `irbench bench track`: renders a short sequence to a temporary folder and
// times the tracker's stages per frame-set on it (images preloaded, so disk
// and PNG decoding are not counted).

#include <string>
#include <vector>

#include "sim/sequence/render_job.h"

namespace irbench {

struct TrackBenchRow {
  std::string stage;
  double median_ms = 0;  // per frame-set, all cameras
  double mean_ms = 0;
};

// `render`'s out is ignored (a temporary folder, removed afterwards).
std::vector<TrackBenchRow> RunTrackBench(RenderJobOptions render, int frames, int repeats, int* cameras);

}  // namespace irbench
