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
  // The render pass's ms per frame-set by stage (they add up to its time):
  // posing, skinning and upload; shadow maps and draw calls; read-back;
  // resampling left after the last read-back; truth (joints, visibility).
  double pose_ms = 0, draw_ms = 0, read_back_ms = 0, resample_ms = 0, truth_ms = 0;
  double encode_ms = 0;     // PNG encoding of frames and masks (encode pass)
};

// Renders `frames` frame-sets of the job's inputs at each resolution scale.
std::vector<RenderBenchResult> RunRenderBench(const RenderJobOptions& options,
                                              const std::vector<double>& scales,
                                              int frames,
                                              std::string* backend_description);

}  // namespace irbench
