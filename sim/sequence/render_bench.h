#pragma once
// `irbench bench render`: throughput of the render path, in frame-sets per
// second (one frame-set = every camera of the rig for one frame).

#include <string>
#include <vector>

#include "sim/sequence/render_job.h"

namespace irbench {

struct RenderBenchResult {
  std::string label;        // e.g. "320x240"
  int cameras = 0;
  int frames = 0;
  double render_fps = 0;    // pose, skin, upload, rasterise, read back, undistort, truth
  double encode_fps = 0;    // the same plus PNG encoding of frames and masks
  double ms_per_camera = 0; // render only
};

// Renders `frames` frame-sets of the job's inputs at each resolution scale.
std::vector<RenderBenchResult> RunRenderBench(const RenderJobOptions& options,
                                              const std::vector<double>& scales,
                                              int frames,
                                              std::string* backend_description);

}  // namespace irbench
