#include "tracker/pipeline/track_job.h"

#include <algorithm>
#include <chrono>
#include <deque>
#include <cmath>
#include <cstdio>
#include <map>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "common/npy.h"
#include "common/atomic_file.h"
#include "common/cancel.h"
#include "common/error.h"
#include "common/logging.h"
#include "common/progress.h"
#include "common/sha256.h"
#include "tracker/frontend/camera_health.h"
#include "tracker/frontend/frontend.h"
#include "tracker/hull/ply.h"
#include "tracker/pipeline/frame_tracker.h"
#include "tracker/pose/pose_tracker.h"

namespace irbench {
namespace fs = std::filesystem;
namespace {

std::string FrameName(int frame) {
  char name[32];
  std::snprintf(name, sizeof(name), "%06d.png", frame);
  return name;
}

void WritePng(const fs::path& path, const cv::Mat& image) {
  std::vector<uchar> bytes;
  if (!cv::imencode(".png", image, bytes)) throw RuntimeError("cannot encode " + path.string());
  AtomicWriteFile(path, std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()));
}

cv::Scalar PartColour(BodyPart part) {
  switch (part) {
    case BodyPart::kHead: return {0, 230, 230};           // yellow
    case BodyPart::kTorso: return {230, 120, 0};          // blue
    case BodyPart::kLeftImageArm: return {230, 0, 230};   // magenta
    case BodyPart::kRightImageArm: return {230, 230, 0};  // cyan
    case BodyPart::kArm: return {230, 230, 0};
    default: return {140, 140, 140};
  }
}

// The model's ellipse outlines in the camera's distorted image.
void DrawModel(cv::Mat* out, const Camera& camera, const PosedBody& body) {
  for (const std::vector<Eigen::Vector2d>& outline : BodyOutlines(camera, body, 48)) {
    std::vector<cv::Point> poly;
    for (const Eigen::Vector2d& p : outline) poly.emplace_back(int(std::lround(p.x())), int(std::lround(p.y())));
    cv::polylines(*out, poly, true, cv::Scalar(0, 140, 255), 1, cv::LINE_AA);
  }
}

cv::Mat Overlay(const cv::Mat& frame, const CameraFeatures& f, const AxisView* view,
                const std::vector<AxisPoint3d>& axis3d) {
  cv::Mat out;
  cv::cvtColor(frame, out, cv::COLOR_GRAY2BGR);
  out.setTo(cv::Scalar(0, 0, 200), f.before_shadows & ~f.silhouette);
  std::vector<std::vector<cv::Point>> contours;
  cv::findContours(f.silhouette.clone(), contours, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_NONE);
  cv::drawContours(out, contours, -1, cv::Scalar(0, 220, 0), 1);
  if (view) {
    for (size_t i = 0; i < view->graph.points.size(); ++i) {
      const BodyPart part = i < view->labels.size() ? view->labels[i] : BodyPart::kNone;
      if (part == BodyPart::kNone) continue;
      const Eigen::Vector2d& p = view->graph.points[i].px;
      out.at<cv::Vec3b>(std::clamp(int(std::lround(p.y())), 0, out.rows - 1),
                        std::clamp(int(std::lround(p.x())), 0, out.cols - 1)) =
          cv::Vec3b(PartColour(part)[0], PartColour(part)[1], PartColour(part)[2]);
    }
    // The 3D axis points projected back: white crosses.
    for (const AxisPoint3d& a : axis3d) {
      const Eigen::Vector3d p_in_cam = view->camera.cam_from_world * a.p_in_world;
      if (p_in_cam.z() <= 0) continue;
      const Eigen::Vector2d px = view->camera.ProjectInCamera(p_in_cam);
      if (!px.allFinite() || px.cwiseAbs().maxCoeff() > 1e5) continue;
      cv::drawMarker(out, cv::Point(int(std::lround(px.x())), int(std::lround(px.y()))), {255, 255, 255},
                     cv::MARKER_CROSS, 3, 1);
    }
  }
  return out;
}

// The front end's options for this job: the settings' (edge scale applied),
// the polyhedral hull built when it is written (--ply).
FrontEndOptions JobFrontEndOptions(const TrackJobOptions& options) {
  FrontEndOptions fe_options = EffectiveFrontEndOptions(options.tracker);
  fe_options.polyhedral_hull = options.ply;
  return fe_options;
}

// The output must not replace, hold or sit inside what it reads: the
// sequence's frames/, background/, calib/, a recording's videos/ and
// calibration files, and the rest-state model (common/atomic_file.h; the
// StagingDir then replaces only irbench's own).
void CheckOutputOutsideSequence(const TrackJobOptions& options) {
  const fs::path out = options.out.empty() ? options.sequence / "track" : options.out;
  std::vector<fs::path> inputs;
  for (const char* part : {"frames", "background", "calib", "videos", "intri.yml", "extri.yml"}) {
    inputs.push_back(options.sequence / part);
  }
  inputs.push_back(options.tracker.rest_model.empty() ? DefaultRestModelPath() : options.tracker.rest_model);
  inputs.push_back(options.tracker.posture_atoms.empty() ? DefaultPostureAtomsPath() : options.tracker.posture_atoms);
  inputs.push_back(options.tracker.gesture_models.empty() ? DefaultGestureModelsPath() : options.tracker.gesture_models);
  if (!options.tracker.motion_labels.empty()) inputs.push_back(options.tracker.motion_labels);
  for (MotionModelKind kind : {MotionModelKind::kCrf, MotionModelKind::kLdcrf}) {
    inputs.push_back(DefaultMotionLabelModelPath(kind));
  }
  CheckOutputApart(out, inputs, "--out");
}

// What a track job holds while it runs over the frames.
struct TrackRun {
  const TrackJobOptions& options;
  const SequenceInput& input;
  FrameTracker& tracker;
  fs::path root;  // the staging folder
  std::string lines, track_lines;
  std::optional<NpyRowWriter> descriptors;
  int descriptor_bins = 0;
  // track.jsonl lines waiting for their motion labels (the labeller's
  // latency), oldest first.
  std::deque<nlohmann::json> pending;

  // Puts motion labels on their pending lines, then writes out every line
  // the labeller is done with (all of them when `all`).
  void PutMotion(const std::vector<MotionLabeler::Labels>& labels, bool all) {
    int done_through = -1;
    for (const MotionLabeler::Labels& l : labels) {
      for (nlohmann::json& line : pending) {
        if (line["frame"].get<int>() == l.frame) line["motion"] = FrameTracker::MotionJson(l);
      }
      done_through = l.frame;
    }
    while (!pending.empty() &&
           (all || !tracker.motion_labeler() || pending.front()["frame"].get<int>() <= done_through)) {
      track_lines += pending.front().dump() + "\n";
      pending.pop_front();
    }
  }
};

// Tracks frame f: the silhouettes (and overlays, PLY) written, a line
// appended to each JSONL.
void TrackFrame(int f, TrackRun& run) {
  const TrackJobOptions& options = run.options;
  const SequenceInput& input = run.input;
  std::vector<std::string> problems;
  std::vector<cv::Mat> read = input.TryFrameSet(f, &problems);
  const FrameTracker::Step step = run.tracker.Track(f, std::move(read), problems, 1.0 / input.fps());
  const FrameFeatures& features = step.features;
  for (size_t c = 0; c < input.cameras().size(); ++c) {
    const std::string& name = input.cameras()[c].name;
    WritePng(run.root / "silhouettes" / name / FrameName(f), features.cameras[c].silhouette);
    if (options.overlays) {
      const AxisView* view = c < features.views.size() ? &features.views[c] : nullptr;
      cv::Mat overlay = Overlay(step.images[c], features.cameras[c], view, features.axis3d);
      if (step.pose && step.pose->tracking) DrawModel(&overlay, input.cameras()[c], step.pose->body);
      WritePng(run.root / "overlays" / name / FrameName(f), overlay);
    }
  }
  if (options.ply) {
    char stem[32];
    std::snprintf(stem, sizeof(stem), "%06d", f);
    if (features.voxels) WriteVoxelCubesPly(run.root / "hull" / (std::string(stem) + "_voxels.ply"), *features.voxels);
    if (features.hull) WriteMeshPly(run.root / "hull" / (std::string(stem) + "_polyhedral.ply"), *features.hull);
    if (step.nss) WriteNssPly(run.root / "hull" / (std::string(stem) + "_nss.ply"), *step.nss);
  }
  if (run.descriptors) {
    run.descriptors->Append(step.shape ? step.shape->bins : std::vector<float>(run.descriptor_bins, 0.0f));
  }
  run.lines += step.features_line.dump() + "\n";
  run.pending.push_back(step.track_line);
  run.PutMotion(step.motion, false);
}

}  // namespace

fs::path RunTrackJob(const TrackJobOptions& options) {
  const TrackerSettings& settings = options.tracker;
  CheckTrackerSettings(settings);
  const FrontEndOptions fe_options = JobFrontEndOptions(options);
  CheckOutputOutsideSequence(options);
  const SequenceInput input = SequenceInput::Open(options.sequence, options.input);
  const std::shared_ptr<const RestClassifier> rest_classifier = LoadRestClassifier(settings);
  int frames = input.frame_count();
  if (options.frames) {
    if (*options.frames < 1) throw InputError("", "--frames", "must be at least 1");
    frames = std::min(frames, *options.frames);
  }
  const fs::path out = options.out.empty() ? options.sequence / "track" : options.out;
  StagingDir staging(out, options.overwrite, "--out", "track");
  const fs::path root = staging.path();
  if (options.ply) fs::create_directories(root / "hull");
  for (const Camera& cam : input.cameras()) {
    fs::create_directories(root / "silhouettes" / cam.name);
    if (options.overlays) fs::create_directories(root / "overlays" / cam.name);
  }
  FrameTracker tracker(input, settings, fe_options, rest_classifier);
  const double train_ms = tracker.train_ms();
  Log().info("track: background models for {} cameras from {} empty-stage frames in {:.0f} ms",
             input.cameras().size(), input.background_count(), train_ms);
  const size_t nc = input.cameras().size();
  TrackRun run{options, input, tracker, root, "", "", std::nullopt, ShapeDescriptorOptions().bin_count(), {}};
  if (options.descriptors) run.descriptors.emplace(root / "descriptors.npy", frames, run.descriptor_bins);
  for (size_t c = 0; c < nc; ++c) {
    if (input.MissingFrames()[c] > 0) {
      Log().warn("track: camera {} lacks {} of {} frames; tracked without it there", input.cameras()[c].name,
                 input.MissingFrames()[c], input.frame_count());
    }
  }
  const auto start = std::chrono::steady_clock::now();
  {
    Progress progress("track", "frame-sets", frames);
    for (int f = 0; f < frames; ++f) {
      ThrowIfCancelled();
      TrackFrame(f, run);
      progress.Set(f + 1, "frame");
    }
  }
  run.PutMotion(tracker.FinishMotion(), true);
  if (run.descriptors) run.descriptors->Close();
  AtomicWriteFile(root / "features.jsonl", run.lines);
  AtomicWriteFile(root / "track.jsonl", run.track_lines);
  nlohmann::json meta = SettingsJson(settings);
  meta.update({{"format", "irbench.track-features/1"},
               {"sequence", fs::absolute(options.sequence).lexically_normal().string()},
               {"frames", frames},
               {"train_ms", train_ms}});
  nlohmann::json left_out = nlohmann::json::object();
  for (size_t c = 0; c < nc; ++c) {
    const std::map<std::string, int>& counts = tracker.left_out_counts()[c];
    if (counts.empty()) continue;
    left_out[input.cameras()[c].name] = counts;
    int total = 0;
    for (const auto& [reason, n] : counts) total += n;
    Log().warn("track: camera {} was left out of {} of {} frame-sets ({})", input.cameras()[c].name, total, frames,
               nlohmann::json(counts).dump());
  }
  meta["cameras_left_out"] = left_out;
  // Where the frames came from: frame files, or a recording's videos and
  // its empty stage (docs/recordings.md).
  nlohmann::json source = {{"kind", input.from_videos() ? "videos" : "frames"}};
  if (input.from_videos()) {
    source["videos"] = nlohmann::json::array();
    for (size_t c = 0; c < nc; ++c) source["videos"].push_back(input.FramePath(static_cast<int>(c), 0).string());
    if (options.input.empty_stage_s) {
      source["empty_stage_s"] = {options.input.empty_stage_s->first, options.input.empty_stage_s->second};
    }
  }
  meta["input"] = source;
  // The model files this track used, by content (what they are is in each
  // file's own header: how it was made).
  nlohmann::json models = nlohmann::json::object();
  if (rest_classifier) {
    const fs::path rest_path = settings.rest_model.empty() ? DefaultRestModelPath() : settings.rest_model;
    models["rest_state"] = {{"file", fs::absolute(rest_path).lexically_normal().string()},
                            {"sha256", Sha256OfFile(rest_path)}};
  }
  if (!tracker.posture_atoms_path().empty()) {
    models["posture_atoms"] = {{"file", fs::absolute(tracker.posture_atoms_path()).lexically_normal().string()},
                               {"sha256", Sha256OfFile(tracker.posture_atoms_path())}};
  }
  if (!tracker.gesture_models_path().empty()) {
    models["gestures"] = {{"file", fs::absolute(tracker.gesture_models_path()).lexically_normal().string()},
                          {"sha256", Sha256OfFile(tracker.gesture_models_path())},
                          {"kind", GestureModelKindName(settings.gesture_model)}};
  }
  if (!tracker.motion_labels_path().empty()) {
    models["motion_labels"] = {{"file", fs::absolute(tracker.motion_labels_path()).lexically_normal().string()},
                               {"sha256", Sha256OfFile(tracker.motion_labels_path())},
                               {"kind", MotionModelKindName(tracker.motion_labeler()->model().kind)},
                               {"latency_frames", tracker.motion_labeler()->latency_frames()}};
  }
  meta["models"] = models;
  AtomicWriteFile(root / "track.json", meta.dump(2) + "\n");
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  Log().info("track: {} frame-sets in {:.1f} s ({:.1f} ms per frame-set incl. I/O)", frames, seconds,
             1000 * seconds / std::max(1, frames));
  staging.Commit();
  return staging.final_path();
}

}  // namespace irbench
