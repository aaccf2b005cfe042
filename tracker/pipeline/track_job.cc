#include "tracker/pipeline/track_job.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "common/atomic_file.h"
#include "common/cancel.h"
#include "common/error.h"
#include "common/logging.h"
#include "common/progress.h"
#include "common/sha256.h"
#include "tracker/frontend/camera_health.h"
#include "tracker/frontend/frontend.h"
#include "tracker/hull/ply.h"
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
      const Eigen::Vector2d px = view->camera.Project(a.p_in_world);
      if (!px.allFinite() || px.cwiseAbs().maxCoeff() > 1e5) continue;
      cv::drawMarker(out, cv::Point(int(std::lround(px.x())), int(std::lround(px.y()))), {255, 255, 255},
                     cv::MARKER_CROSS, 3, 1);
    }
  }
  return out;
}

// A world point as JSON, to 0.1 mm.
nlohmann::json Rounded(const Eigen::Vector3d& p) {
  return {std::round(p.x() * 1e4) / 1e4, std::round(p.y() * 1e4) / 1e4, std::round(p.z() * 1e4) / 1e4};
}

const char* Part3dName(BodyPart part) {
  switch (part) {
    case BodyPart::kHead: return "head";
    case BodyPart::kTorso: return "torso";
    default: return "arm";
  }
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
  CheckOutputApart(out, inputs, "--out");
}

// The rest-state model (pose stage), loaded before any work is done; null
// (with a warning) when the default model is absent.
std::shared_ptr<const RestClassifier> LoadRestClassifier(const TrackerSettings& settings) {
  if (settings.stage != TrackStage::kPose) return nullptr;
  const fs::path rest_path = settings.rest_model.empty() ? DefaultRestModelPath() : settings.rest_model;
  if (!settings.rest_model.empty() || fs::exists(rest_path)) {
    return std::make_shared<RestClassifier>(RestClassifier::Load(rest_path));
  }
  Log().warn("track: no rest-state model at {} (irbench train rest); rest stays null", rest_path.string());
  return nullptr;
}

// features.jsonl's per-camera entry: silhouette area, axis points by part,
// polygon edges, shadow pixels removed, light level, blobs removed.
nlohmann::json CameraFeaturesJson(const FrameFeatures& features, size_t c) {
  const CameraFeatures& cf = features.cameras[c];
  std::map<std::string, int> parts;
  if (c < features.views.size()) {
    const AxisView& v = features.views[c];
    int kept = 0;
    for (const AxisPoint2d& p : v.graph.points) kept += p.kept;
    parts["axis_points"] = kept;
    for (BodyPart b : v.labels) {
      if (b != BodyPart::kNone) ++parts[BodyPartName(b)];
    }
  }
  nlohmann::json j;
  j["health"] = CameraHealthName(cf.health);
  j["mean_level"] = std::round(cf.mean_level * 100) / 100;
  j["polygon_edges"] = c < features.polygons.size() ? features.polygons[c].EdgeCount() : 0;
  j.update({{"silhouette_area", cv::countNonZero(cf.silhouette)},
            {"axis", parts},
            {"shadow_pixels_removed", cv::countNonZero(cf.before_shadows & ~cf.silhouette)},
            {"light_level", cf.light_level},
            {"blobs_removed", cf.blobs_removed}});
  return j;
}

// features.jsonl's hull part: 3D axis points, voxels, placement, polyhedral hull.
void AddHullFeatures(const FrameFeatures& features, const std::vector<Camera>& cameras, nlohmann::json& line) {
  nlohmann::json axis3d = nlohmann::json::array();
  for (const AxisPoint3d& a : features.axis3d) {
    axis3d.push_back({{"p", Rounded(a.p_in_world)},
                      {"part", Part3dName(a.part)},
                      {"diameter_m", std::round(a.diameter_m * 1e4) / 1e4},
                      {"support", a.support}});
  }
  line["axis3d"] = axis3d;
  if (features.voxels) {
    line["voxels"] = {{"occupied", features.voxels->occupied_count},
                      {"volume_m3", std::round(features.voxels->VolumeM3() * 1e5) / 1e5},
                      {"voxel_size_m", features.voxels->voxel_size_m}};
  }
  line["placement"] =
      features.placement
          ? nlohmann::json{{"root", Rounded(features.placement->root)},
                           {"top_m", std::round(features.placement->top_m * 1e3) / 1e3},
                           {"dropped_view", features.placement->dropped_view < 0
                                                ? nlohmann::json(nullptr)
                                                : nlohmann::json(cameras[features.placement->dropped_view].name)},
                           {"dropped_view_coverage", std::round(features.placement->dropped_view_coverage * 1e3) / 1e3}}
          : nlohmann::json(nullptr);
  line["polyhedral_hull"] =
      features.hull ? nlohmann::json{{"vertices", features.hull->vertices.size()},
                                     {"triangles", features.hull->triangles.size()},
                                     {"volume_m3", std::round(MeshVolume(*features.hull) * 1e5) / 1e5}}
                    : nlohmann::json(nullptr);
}

// track.jsonl's pointing rays (right, left) with their screen hits.
nlohmann::json PointingJson(const PoseEstimate& pose) {
  nlohmann::json pointing = nlohmann::json::object();
  for (int side = 0; side < 2; ++side) {
    const auto& ray = pose.pointing[side];
    nlohmann::json j = nullptr;
    if (ray) {
      j = {{"origin", Rounded(ray->origin)}, {"dir", Rounded(ray->dir)}, {"screen", nullptr},
           {"screen_hit", nullptr}, {"target", nullptr}};
      if (ray->screen_hit) {
        j["screen"] = *ray->screen;
        j["screen_hit"] = {std::round(ray->screen_hit->x() * 1e4) / 1e4, std::round(ray->screen_hit->y() * 1e4) / 1e4};
        if (ray->target) j["target"] = *ray->target;
      }
    }
    pointing[side == 0 ? "right" : "left"] = j;
  }
  return pointing;
}

// A track.jsonl line (docs/architecture.md, "Tracker output"): what the stages
// built so far know; everything else null, never invented. Adds the pose's
// per-camera overlap to the features line.
nlohmann::json TrackLine(int f, double t, const FrameFeatures& features, const std::optional<PoseEstimate>& pose,
                         const std::vector<Camera>& cameras, nlohmann::json& line) {
  nlohmann::json track_line;
  track_line["frame"] = f;
  track_line["t"] = t;
  const bool tracking = pose ? pose->tracking : features.placement.has_value();
  // "partial": someone is there but not yet (or no longer) in every view.
  track_line["state"] = tracking ? "tracking" : (pose && features.placement && !pose->in_view) ? "partial" : "empty";
  nlohmann::json joints = nlohmann::json::object();
  for (const char* name : {"root", "waist", "neck", "head", "left_shoulder", "left_elbow", "left_wrist",
                           "left_hand_tip", "right_shoulder", "right_elbow", "right_wrist", "right_hand_tip",
                           "left_hip", "left_knee", "left_ankle", "right_hip", "right_knee", "right_ankle"}) {
    joints[name] = nullptr;
  }
  for (const char* key : {"dof", "pointing", "rest", "posture", "gesture", "motion"}) track_line[key] = nullptr;
  track_line["height_m"] = nullptr;
  if (pose && pose->tracking) {
    for (int j = 0; j < kModelJointCount; ++j) joints[ModelJointName(j)] = Rounded(pose->body.joints[j]);
    nlohmann::json dof = nlohmann::json::object();
    for (int d = 0; d < kDofCount; ++d) dof[BodyDofName(d)] = std::round(pose->pose.dof[d] * 1e5) / 1e5;
    track_line["dof"] = dof;
    track_line["pointing"] = PointingJson(*pose);
    if (pose->rest[0] && pose->rest[1]) track_line["rest"] = {{"right", *pose->rest[0]}, {"left", *pose->rest[1]}};
    track_line["height_m"] = std::round(pose->shape.height_m * 1e3) / 1e3;
    track_line["girth"] = std::round(pose->shape.girth * 1e3) / 1e3;
    track_line["arm_thickness"] = std::round(pose->shape.arm_thickness * 1e3) / 1e3;
    nlohmann::json overlap = nlohmann::json::object();
    for (size_t c = 0; c < pose->overlap.size(); ++c) {
      overlap[cameras[c].name] =
          std::isnan(pose->overlap[c]) ? nlohmann::json(nullptr) : nlohmann::json(std::round(pose->overlap[c] * 1e4) / 1e4);
    }
    line["pose_overlap"] = overlap;
  } else if (!pose && features.placement) {
    const Eigen::Vector3d& r = features.placement->root;
    joints["root"] = {std::round(r.x() * 1e4) / 1e4, std::round(r.y() * 1e4) / 1e4, 0.0};
    track_line["height_m"] = std::round(features.placement->top_m * 1e3) / 1e3;
  }
  track_line["joints3d"] = joints;
  // The cameras this frame-set was tracked without, and why (camera_health.h).
  nlohmann::json left_out = nlohmann::json::object();
  for (size_t c = 0; c < features.cameras.size(); ++c) {
    if (features.LeftOut(c)) left_out[cameras[c].name] = CameraHealthName(features.cameras[c].health);
  }
  track_line["cameras_left_out"] = left_out;
  return track_line;
}

// Milliseconds per stage, for both lines.
nlohmann::json StageMs(const FrameFeatures& features, const std::optional<PoseEstimate>& pose) {
  nlohmann::json ms = {{"silhouettes", features.ms_silhouettes}, {"axes", features.ms_axes},
                       {"polygons", features.ms_polygons},       {"voxels", features.ms_voxels},
                       {"polyhedral_hull", features.ms_polyhedral}};
  if (pose) {
    ms["pose"] = pose->ms_total;
    ms["pose_observation"] = pose->ms_observation;
    ms["pose_refine"] = pose->ms_refine;
  }
  return ms;
}

// What a track job holds while it runs over the frames.
struct TrackRun {
  const TrackJobOptions& options;
  const SequenceInput& input;
  const FrontEnd& front_end;
  std::optional<PoseTracker>& pose_tracker;
  fs::path root;  // the staging folder
  std::string lines, track_lines;
  CameraHealthMonitor health;
  std::vector<CameraHealth> last_health;  // per camera, to warn on changes
  std::vector<std::map<std::string, int>> left_out_counts;  // per camera, frame-sets by reason
};

// Reads frame-set f, tolerating faults, and decides which cameras to leave
// out; warns when a camera's state changes.
std::vector<cv::Mat> ReadFrameSet(int f, TrackRun& run, std::vector<CameraStatus>* status) {
  const SequenceInput& input = run.input;
  std::vector<std::string> problems;
  std::vector<cv::Mat> images = input.TryFrameSet(f, &problems);
  *status = run.health.Update(images);
  for (size_t c = 0; c < images.size(); ++c) {
    const CameraHealth h = (*status)[c].health;
    const std::string& name = input.cameras()[c].name;
    if (h != run.last_health[c] && h == CameraHealth::kOk) {
      Log().warn("track: camera {} ok again from frame {}", name, f);
    } else if (h != run.last_health[c]) {
      Log().warn("track: camera {} {} from frame {}{}{}", name, CameraHealthName(h), f,
                 problems[c].empty() ? "" : " (" + problems[c] + ")",
                 h == CameraHealth::kMissing || run.front_end.options().health.leave_out ? ": left out" : "");
    } else if (!problems[c].empty()) {
      Log().debug("track: frame {} of camera {} skipped: {}", f, name, problems[c]);
    }
    run.last_health[c] = h;
    // A missing frame is drawn black (silhouettes, overlays).
    if (images[c].empty()) images[c] = cv::Mat::zeros(input.cameras()[c].height, input.cameras()[c].width, CV_8U);
  }
  return images;
}

// Processes frame f: front end, pose, the silhouettes (and overlays, PLY)
// written, a line appended to each JSONL.
void TrackFrame(int f, TrackRun& run) {
  const TrackJobOptions& options = run.options;
  const SequenceInput& input = run.input;
  std::vector<CameraStatus> status;
  const std::vector<cv::Mat> images = ReadFrameSet(f, run, &status);
  std::vector<bool> left_out(status.size());
  for (size_t c = 0; c < status.size(); ++c) {
    left_out[c] = status[c].health == CameraHealth::kMissing ||
                  (!status[c].usable() && run.front_end.options().health.leave_out);
    if (left_out[c]) ++run.left_out_counts[c][CameraHealthName(status[c].health)];
  }
  FrameFeatures features = run.front_end.Process(f, images, left_out);
  for (size_t c = 0; c < status.size(); ++c) {
    features.cameras[c].health = status[c].health;
    features.cameras[c].mean_level = status[c].mean_level;
  }
  std::optional<PoseEstimate> pose;
  if (run.pose_tracker) pose = run.pose_tracker->Step(features, 1.0 / input.fps());
  nlohmann::json line;
  line["frame"] = f;
  line["t"] = f / input.fps();
  for (size_t c = 0; c < input.cameras().size(); ++c) {
    const std::string& name = input.cameras()[c].name;
    line["cameras"][name] = CameraFeaturesJson(features, c);
    WritePng(run.root / "silhouettes" / name / FrameName(f), features.cameras[c].silhouette);
    if (options.overlays) {
      const AxisView* view = c < features.views.size() ? &features.views[c] : nullptr;
      cv::Mat overlay = Overlay(images[c], features.cameras[c], view, features.axis3d);
      if (pose && pose->tracking) DrawModel(&overlay, input.cameras()[c], pose->body);
      WritePng(run.root / "overlays" / name / FrameName(f), overlay);
    }
  }
  AddHullFeatures(features, input.cameras(), line);
  nlohmann::json track_line = TrackLine(f, f / input.fps(), features, pose, input.cameras(), line);
  line["ms"] = StageMs(features, pose);
  if (options.ply) {
    char stem[32];
    std::snprintf(stem, sizeof(stem), "%06d", f);
    if (features.voxels) WriteVoxelCubesPly(run.root / "hull" / (std::string(stem) + "_voxels.ply"), *features.voxels);
    if (features.hull) WriteMeshPly(run.root / "hull" / (std::string(stem) + "_polyhedral.ply"), *features.hull);
  }
  track_line["ms"] = line["ms"];
  run.lines += line.dump() + "\n";
  run.track_lines += track_line.dump() + "\n";
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
  const auto train_start = std::chrono::steady_clock::now();
  const FrontEnd front_end = FrontEnd::Train(input, fe_options);
  const double train_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - train_start).count();
  Log().info("track: background models for {} cameras from {} empty-stage frames in {:.0f} ms",
             input.cameras().size(), input.background_count(), train_ms);

  std::optional<PoseTracker> pose_tracker;
  if (settings.stage == TrackStage::kPose) {
    pose_tracker.emplace(input.cameras(), input.screens(), settings.pose);
    if (rest_classifier) pose_tracker->set_rest_classifier(rest_classifier);
  }
  const size_t nc = input.cameras().size();
  TrackRun run{options, input, front_end, pose_tracker, root, "", "",
               CameraHealthMonitor(front_end.camera_references(), fe_options.health),
               std::vector<CameraHealth>(nc, CameraHealth::kOk), std::vector<std::map<std::string, int>>(nc)};
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
  AtomicWriteFile(root / "features.jsonl", run.lines);
  AtomicWriteFile(root / "track.jsonl", run.track_lines);
  nlohmann::json meta = SettingsJson(settings);
  meta.update({{"format", "irbench.track-features/1"},
               {"sequence", fs::absolute(options.sequence).lexically_normal().string()},
               {"frames", frames},
               {"train_ms", train_ms}});
  nlohmann::json left_out = nlohmann::json::object();
  for (size_t c = 0; c < nc; ++c) {
    if (run.left_out_counts[c].empty()) continue;
    left_out[input.cameras()[c].name] = run.left_out_counts[c];
    int total = 0;
    for (const auto& [reason, n] : run.left_out_counts[c]) total += n;
    Log().warn("track: camera {} was left out of {} of {} frame-sets ({})", input.cameras()[c].name, total, frames,
               nlohmann::json(run.left_out_counts[c]).dump());
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
  meta["models"] = models;
  AtomicWriteFile(root / "track.json", meta.dump(2) + "\n");
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  Log().info("track: {} frame-sets in {:.1f} s ({:.1f} ms per frame-set incl. I/O)", frames, seconds,
             1000 * seconds / std::max(1, frames));
  staging.Commit();
  return staging.final_path();
}

}  // namespace irbench
