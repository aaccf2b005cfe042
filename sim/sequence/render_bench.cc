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
    for (bool encode : {false, true}) {
      // Five warm-up frame-sets (shader variants compile on first use), then
      // the timed ones.
      std::chrono::steady_clock::time_point start;
      for (int f = -5; f < frames; ++f) {
        if (f == 0) {
          Log().debug("bench: timing {} encode={}", result.label, encode);
          start = std::chrono::steady_clock::now();
        }
        ThrowIfCancelled();
        const double t = std::max(0, f) / in.fps;
        const JointTransforms world_from_joint = PoseAndUpload(in, t, renderer, skinned);
        renderer.RenderAll(&images, false);
        if (encode) {
          for (const CameraImages& image : images) {
            volatile size_t sink = EncodePng(image.grey).size() + EncodePng(image.mask).size();
            (void)sink;
          }
        }
        const FrameTruth truth = ComputeFrameTruth(in, world_from_joint, renderer);
        (void)truth;
        if (f == frames - 1) {
          const double seconds =
              std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
          (encode ? result.encode_fps : result.render_fps) = frames / seconds;
          if (!encode) result.ms_per_camera = 1000.0 * seconds / (frames * cameras.size());
        }
      }
    }
    Log().info("bench: {} done", result.label);
    results.push_back(result);
  }
  return results;
}

}  // namespace irbench
