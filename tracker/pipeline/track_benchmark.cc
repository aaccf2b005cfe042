#include "tracker/pipeline/track_benchmark.h"

#include <algorithm>
#include <chrono>
#include <memory>
#include <opencv2/core/utility.hpp>
#include <utility>

#include "common/logging.h"
#include "tracker/frontend/frontend.h"
#include "tracker/pipeline/frame_tracker.h"
#include "tracker/pose/pose_tracker.h"

namespace irbench {
namespace {

namespace fs = std::filesystem;

// Per-frame-set milliseconds, one sample per frame-set and pass.
struct FrontEndSamples {
  std::vector<double> silhouettes, axes, polygons, voxels, polyhedral, tracked, total, one_thread;
};

// Milliseconds of the stages irbench track runs (all but the polyhedral hull).
double TrackedMs(const FrameFeatures& f) {
  return f.ms_silhouettes + f.ms_axes + f.ms_polygons + f.ms_voxels;
}

// The median and mean of `samples_ms` as the row of `stage`.
TrackBenchRow SummaryRow(const std::string& stage, std::vector<double> samples_ms) {
  std::sort(samples_ms.begin(), samples_ms.end());
  double sum = 0;
  for (double x : samples_ms) sum += x;
  return TrackBenchRow{stage, samples_ms[samples_ms.size() / 2], sum / samples_ms.size()};
}

// Every frame-set of `input` in memory, so that decoding is not timed.
std::vector<std::vector<cv::Mat>> PreloadFrameSets(const SequenceInput& input) {
  std::vector<std::vector<cv::Mat>> images(input.frame_count());
  for (int f = 0; f < input.frame_count(); ++f) images[f] = input.FrameSet(f);
  return images;
}

// Times `repeats` passes of the front end with OpenCV's threads; returns the first pass's features.
std::vector<FrameFeatures> TimeFrontEnd(const FrontEnd& front_end,
                                        const std::vector<std::vector<cv::Mat>>& images,
                                        int repeats,
                                        FrontEndSamples* samples) {
  std::vector<FrameFeatures> all_features;
  for (int r = 0; r < repeats; ++r) {
    for (int f = 0; f < static_cast<int>(images.size()); ++f) {
      const auto start = std::chrono::steady_clock::now();
      FrameFeatures features = front_end.Process(f, images[f]);
      samples->total.push_back(
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
              .count());
      samples->silhouettes.push_back(features.ms_silhouettes);
      samples->axes.push_back(features.ms_axes);
      samples->polygons.push_back(features.ms_polygons);
      samples->voxels.push_back(features.ms_voxels);
      samples->polyhedral.push_back(features.ms_polyhedral);
      samples->tracked.push_back(TrackedMs(features));
      if (r == 0) all_features.push_back(std::move(features));
    }
  }
  return all_features;
}

// The same passes on one thread: how much the cores add (the front end's work
// divided among them), and a figure less moved by a busy machine.
std::vector<double> TimeFrontEndOneThread(const FrontEnd& front_end,
                                          const std::vector<std::vector<cv::Mat>>& images,
                                          int repeats) {
  std::vector<double> one_thread;
  const int threads = cv::getNumThreads();
  cv::setNumThreads(1);
  for (int r = 0; r < repeats; ++r) {
    for (int f = 0; f < static_cast<int>(images.size()); ++f) {
      one_thread.push_back(TrackedMs(front_end.Process(f, images[f])));
    }
  }
  cv::setNumThreads(threads);
  return one_thread;
}

// The front end's rows, in the order the table prints them.
std::vector<TrackBenchRow> FrontEndRows(const FrontEndSamples& s) {
  return {
      SummaryRow("silhouettes (background model, morphology, shadow removal)", s.silhouettes),
      SummaryRow("2D axis points, body parts, 3D axis points", s.axes),
      SummaryRow("silhouette polygons", s.polygons),
      SummaryRow("voxel hull (2 cm, look-up table)", s.voxels),
      SummaryRow("polyhedral hull (on request)", s.polyhedral),
      SummaryRow("front end as irbench track runs it (the stages above but the polyhedral hull)",
                 s.tracked),
      SummaryRow("the same on one thread", s.one_thread),
      SummaryRow("front end, all stages (polyhedral hull included)", s.total)};
}

// The shipped rest-state classifier, as irbench track runs it, where the data
// root has it; else null, with a warning.
std::shared_ptr<const RestClassifier> LoadRestClassifierIfPresent() {
  if (fs::exists(DefaultRestModelPath())) {
    return std::make_shared<const RestClassifier>(RestClassifier::Load(DefaultRestModelPath()));
  }
  Log().warn("bench track: no rest-state model at {}; the pose rows leave the rest state out",
             DefaultRestModelPath().string());
  return nullptr;
}

// Milliseconds per frame-set of the pose tracker with `particles` particles
// over `repeats` passes, on the frame-sets where it tracks.
std::vector<double> TimePoseTracker(const SequenceInput& input,
                                    const std::vector<FrameFeatures>& all_features,
                                    const std::shared_ptr<const RestClassifier>& rest,
                                    int particles,
                                    int repeats) {
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
  return pose_ms;
}

// The pose tracker's rows (thesis 6.3) against particle count; a count where it never tracks has
// none.
std::vector<TrackBenchRow> PoseRows(const SequenceInput& input,
                                    const std::vector<FrameFeatures>& all_features,
                                    int repeats) {
  const std::shared_ptr<const RestClassifier> rest = LoadRestClassifierIfPresent();
  std::vector<TrackBenchRow> rows;
  for (int particles : {25, 50, 100, 200, 400}) {
    std::vector<double> pose_ms = TimePoseTracker(input, all_features, rest, particles, repeats);
    if (pose_ms.empty()) continue;
    rows.push_back(SummaryRow("pose tracker, " + std::to_string(particles) +
                                  " particles (20% refined by ICP" + (rest ? ", rest state" : "") +
                                  ")",
                              std::move(pose_ms)));
  }
  return rows;
}

// The recognition rows (thesis 4.3, 5.1, 5.2) as irbench track runs them
// with its defaults (the shipped posture atoms and gesture models): the
// shape descriptor, then the posture decomposition with the gesture
// models' update, per frame-set with a descriptor; none without atoms.
std::vector<TrackBenchRow> RecognitionRows(const SequenceInput& input,
                                           const std::vector<std::vector<cv::Mat>>& images,
                                           int repeats) {
  const TrackerSettings settings;
  const std::shared_ptr<const RestClassifier> rest = LoadRestClassifierIfPresent();
  std::vector<double> shape_ms, recognition_ms, both_ms;
  for (int r = 0; r < repeats; ++r) {
    FrameTracker tracker(input, settings, EffectiveFrontEndOptions(settings), rest);
    if (tracker.posture_atoms_path().empty()) {
      Log().warn("bench track: no posture atoms; the recognition rows are left out");
      return {};
    }
    for (size_t f = 0; f < images.size(); ++f) {
      const FrameTracker::Step step =
          tracker.Track(static_cast<int>(f), images[f], std::vector<std::string>(images[f].size()), 1.0 / input.fps());
      if (!step.shape) continue;
      const double shape = step.features_line["ms"]["shape"].get<double>();
      const double recognition = step.features_line["ms"]["postures_gestures"].get<double>();
      shape_ms.push_back(shape);
      recognition_ms.push_back(recognition);
      both_ms.push_back(shape + recognition);
    }
  }
  if (both_ms.empty()) return {};
  return {SummaryRow("shape descriptor of the voxel hull (4.3)", std::move(shape_ms)),
          SummaryRow("postures and the gesture models' update (5.1, 5.2)", std::move(recognition_ms)),
          SummaryRow("descriptor + postures + gestures", std::move(both_ms))};
}

}  // namespace

std::vector<TrackBenchRow> RunTrackBenchmark(const fs::path& sequence, int repeats, int* cameras) {
  const SequenceInput input = SequenceInput::Open(sequence);
  *cameras = static_cast<int>(input.cameras().size());
  FrontEndOptions options;
  options.polyhedral_hull = true;  // timed too, though the front end builds it only on request
  const FrontEnd front_end = FrontEnd::Train(input, options);
  const std::vector<std::vector<cv::Mat>> images = PreloadFrameSets(input);
  FrontEndSamples samples;
  const std::vector<FrameFeatures> all_features =
      TimeFrontEnd(front_end, images, repeats, &samples);
  samples.one_thread = TimeFrontEndOneThread(front_end, images, repeats);
  std::vector<TrackBenchRow> rows = FrontEndRows(samples);
  for (TrackBenchRow& row : PoseRows(input, all_features, repeats)) rows.push_back(std::move(row));
  for (TrackBenchRow& row : RecognitionRows(input, images, repeats)) rows.push_back(std::move(row));
  return rows;
}

}  // namespace irbench
