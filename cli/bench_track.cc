#include "cli/bench_track.h"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <memory>
#include <opencv2/core/utility.hpp>

#include "common/logging.h"
#include "tracker/frontend/frontend.h"
#include "tracker/pose/pose_tracker.h"

namespace irbench {
namespace fs = std::filesystem;

std::vector<TrackBenchRow> RunTrackBench(RenderJobOptions render, int frames, int repeats, int* cameras) {
  const fs::path dir = fs::temp_directory_path() / ("irbench_bench_track_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  struct Cleanup {
    fs::path dir;
    ~Cleanup() {
      std::error_code ec;
      fs::remove_all(dir, ec);
    }
  } cleanup{dir};
  render.frames = frames;
  fs::create_directories(dir);
  render.out = dir / "seq";
  if (render.background_frames < 2) render.background_frames = 12;
  Log().info("bench track: rendering {} frame-sets", frames);
  const fs::path seq = RunRenderJob(render);
  const SequenceInput input = SequenceInput::Open(seq);
  *cameras = static_cast<int>(input.cameras().size());
  FrontEndOptions options;
  options.polyhedral_hull = true;  // timed too, though the front end builds it only on request
  const FrontEnd front_end = FrontEnd::Train(input, options);
  std::vector<std::vector<cv::Mat>> images(input.frame_count());
  for (int f = 0; f < input.frame_count(); ++f) images[f] = input.FrameSet(f);
  // The stages irbench track runs (all but the polyhedral hull).
  auto tracked_ms = [](const FrameFeatures& f) { return f.ms_silhouettes + f.ms_axes + f.ms_polygons + f.ms_voxels; };
  std::vector<double> sil, axes, polygons, voxels, polyhedral, tracked, total;
  std::vector<FrameFeatures> all_features;
  for (int r = 0; r < repeats; ++r) {
    for (int f = 0; f < input.frame_count(); ++f) {
      const auto start = std::chrono::steady_clock::now();
      FrameFeatures features = front_end.Process(f, images[f]);
      total.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
      sil.push_back(features.ms_silhouettes);
      axes.push_back(features.ms_axes);
      polygons.push_back(features.ms_polygons);
      voxels.push_back(features.ms_voxels);
      polyhedral.push_back(features.ms_polyhedral);
      tracked.push_back(tracked_ms(features));
      if (r == 0) all_features.push_back(std::move(features));
    }
  }
  // The same on one thread: how much the cores add (the front end's work
  // divided among them), and a figure less moved by a busy machine.
  std::vector<double> one_thread;
  {
    const int threads = cv::getNumThreads();
    cv::setNumThreads(1);
    for (int r = 0; r < repeats; ++r) {
      for (int f = 0; f < input.frame_count(); ++f) {
        one_thread.push_back(tracked_ms(front_end.Process(f, images[f])));
      }
    }
    cv::setNumThreads(threads);
  }
  auto row = [](const std::string& stage, std::vector<double> v) {
    std::sort(v.begin(), v.end());
    double sum = 0;
    for (double x : v) sum += x;
    return TrackBenchRow{stage, v[v.size() / 2], sum / v.size()};
  };
  std::vector<TrackBenchRow> rows = {
      row("silhouettes (background model, morphology, shadow removal)", sil),
      row("2D axis points, body parts, 3D axis points", axes), row("silhouette polygons", polygons),
      row("voxel hull (2 cm, look-up table)", voxels), row("polyhedral hull (on request)", polyhedral),
      row("front end as irbench track runs it (the stages above but the polyhedral hull)", tracked),
      row("the same on one thread", one_thread),
      row("front end, all stages (polyhedral hull included)", total)};
  // The pose tracker (thesis 6.3) against particle count, on the same
  // features; frame-sets where it tracks. With the shipped rest-state
  // classifier, as irbench track runs it, where the data root has it.
  std::shared_ptr<const RestClassifier> rest;
  if (fs::exists(DefaultRestModelPath())) {
    rest = std::make_shared<const RestClassifier>(RestClassifier::Load(DefaultRestModelPath()));
  } else {
    Log().warn("bench track: no rest-state model at {}; the pose rows leave the rest state out",
               DefaultRestModelPath().string());
  }
  for (int particles : {25, 50, 100, 200, 400}) {
    std::vector<double> pose_ms;
    for (int r = 0; r < repeats; ++r) {
      PoseTrackerOptions pose_options;
      pose_options.particles = particles;
      PoseTracker tracker(input.cameras(), input.screens(), pose_options);
      if (rest) tracker.set_rest_classifier(rest);
      for (const FrameFeatures& features : all_features) {
        const PoseEstimate e = tracker.Step(features, 1.0 / input.fps());
        if (e.tracking) pose_ms.push_back(e.ms_total);
      }
    }
    if (pose_ms.empty()) continue;
    TrackBenchRow pose_row = row("pose tracker, " + std::to_string(particles) + " particles (20% refined by ICP" +
                                     (rest ? ", rest state" : "") + ")",
                                 pose_ms);
    rows.push_back(pose_row);
  }
  return rows;
}

}  // namespace irbench
