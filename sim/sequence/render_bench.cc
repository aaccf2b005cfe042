#include "sim/sequence/render_bench.h"

#include <chrono>

#include "common/cancel.h"
#include "common/logging.h"
#include "sim/sequence/image_io.h"

namespace irbench {

std::vector<RenderBenchResult> RunRenderBench(const RenderJobOptions& options,
                                              const std::vector<double>& scales,
                                              int frames,
                                              std::string* backend_description) {
  RenderInputs in = LoadRenderInputs(options);
  auto context = CreateGlContext(options.backend);
  *backend_description = context->BackendName() + ": " + context->RendererString();
  std::vector<RenderBenchResult> results;
  const std::vector<Camera> base_cameras = in.rig.cameras;
  for (double scale : scales) {
    std::vector<Camera> cameras;
    for (const Camera& cam : base_cameras) cameras.push_back(cam.Scaled(scale));
    in.rig.cameras = cameras;
    Renderer renderer(*context, cameras, RenderOptionsFor(options, in));
    renderer.SetScene(in.scene);
    renderer.SetPersonTopology(in.avatar.indices, in.avatar.bind_vertices.size());
    std::vector<MeshVertex> skinned;
    std::vector<CameraImages> images;
    RenderBenchResult result;
    result.label = std::to_string(cameras[0].width) + "x" + std::to_string(cameras[0].height);
    result.cameras = static_cast<int>(cameras.size());
    result.frames = frames;
    using Clock = std::chrono::steady_clock;
    const auto ms = [](Clock::time_point a, Clock::time_point b) {
      return std::chrono::duration<double, std::milli>(b - a).count();
    };
    for (bool encode : {false, true}) {
      // Five warm-up frame-sets (shader variants compile on first use), then
      // the timed ones.
      Clock::time_point start;
      double pose_ms = 0, truth_ms = 0, encode_ms = 0;
      for (int f = -5; f < frames; ++f) {
        if (f == 0) {
          Log().debug("bench: timing {} encode={}", result.label, encode);
          renderer.ResetStageTimes();
          pose_ms = truth_ms = encode_ms = 0;
          start = Clock::now();
        }
        ThrowIfCancelled();
        const double t = std::max(0, f) / in.fps;
        const Clock::time_point t0 = Clock::now();
        const JointTransforms world_from_joint = PoseAndUpload(in, t, renderer, skinned);
        const Clock::time_point t1 = Clock::now();
        renderer.RenderAll(&images, false);
        const Clock::time_point t2 = Clock::now();
        if (encode) {
          for (const CameraImages& image : images) {
            volatile size_t sink = EncodePng(image.grey).size() + EncodePng(image.mask).size();
            (void)sink;
          }
        }
        const Clock::time_point t3 = Clock::now();
        const FrameTruth truth = ComputeFrameTruth(in, world_from_joint, renderer);
        (void)truth;
        pose_ms += ms(t0, t1);
        encode_ms += ms(t2, t3);
        truth_ms += ms(t3, Clock::now());
        if (f == frames - 1) {
          const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
          (encode ? result.encode_fps : result.render_fps) = frames / seconds;
          if (encode) {
            result.encode_ms = encode_ms / frames;
          } else {
            const Renderer::StageTimes& stages = renderer.stage_times();
            result.ms_per_camera = 1000.0 * seconds / (frames * cameras.size());
            result.pose_ms = pose_ms / frames;
            result.draw_ms = 1000.0 * stages.draw_s / frames;
            result.read_back_ms = 1000.0 * stages.read_back_s / frames;
            result.resample_ms = 1000.0 * stages.resample_wait_s / frames;
            result.truth_ms = truth_ms / frames;
          }
        }
      }
    }
    Log().info("bench: {} done", result.label);
    results.push_back(result);
  }
  return results;
}

}  // namespace irbench
