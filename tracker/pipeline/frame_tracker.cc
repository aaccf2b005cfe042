#include "tracker/pipeline/frame_tracker.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <utility>

#include "common/logging.h"
#include "sequence_format/posture_labels.h"
#include "tracker/body_model/body_model.h"

namespace irbench {
namespace fs = std::filesystem;
namespace {

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
    // The configured model's proportions (thesis 6.1.1), as irbench avatar
    // info gives an avatar's: between joint centres.
    track_line["shoulder_width_m"] = std::round(2 * pose->shape.shoulder_offset_m * 1e3) / 1e3;
    track_line["upper_arm_m"] = std::round(pose->shape.upper_arm_m * 1e3) / 1e3;
    track_line["forearm_m"] = std::round(pose->shape.forearm_m * 1e3) / 1e3;
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

// The frame's shape descriptor: the hull's surface for the tracked user's
// height, or the hull's top while the pose tracker has none.
std::optional<ShapeDescriptor> Shape(const FrameFeatures& features, const std::optional<PoseEstimate>& pose,
                                     const ShapeDescriptorOptions& options) {
  if (!features.voxels || !features.placement) return std::nullopt;
  const double height_m = pose && pose->tracking ? pose->shape.height_m : features.placement->top_m;
  if (!(height_m > 0.3)) return std::nullopt;
  return HullShapeDescriptor(*features.voxels, height_m, options);
}

// features.jsonl's summary of the descriptor (the whole one: irbench track
// --descriptors).
// features.jsonl's `nss`: the voxels used and each labelled curve's points
// (world metres, to the millimetre), junction first; null without a hull.
nlohmann::json NssJson(const std::optional<NssSkeleton>& nss) {
  if (!nss) return nullptr;
  nlohmann::json curves = nlohmann::json::object();
  for (const NssCurve& c : nss->curves) {
    nlohmann::json points = nlohmann::json::array();
    for (const Eigen::Vector3d& p : c.points_in_world) {
      points.push_back({std::round(p.x() * 1e3) / 1e3, std::round(p.y() * 1e3) / 1e3, std::round(p.z() * 1e3) / 1e3});
    }
    // Unlabelled limbs get numbered keys: limb, limb_2, ...
    std::string key = c.label;
    for (int n = 2; curves.contains(key); ++n) key = c.label + "_" + std::to_string(n);
    curves[key] = points;
  }
  return {{"voxels", nss->voxels}, {"nodes", nss->nodes.size()}, {"curves", curves}};
}

nlohmann::json ShapeJson(const std::optional<ShapeDescriptor>& shape) {
  if (!shape) return nullptr;
  return {{"points", shape->point_count},
          {"nonempty_bins", shape->NonEmptyBins()},
          {"height_m", std::round(shape->height_m * 1e3) / 1e3},
          {"axis", {std::round(shape->axis_xy.x() * 1e4) / 1e4, std::round(shape->axis_xy.y() * 1e4) / 1e4}}};
}

// track.jsonl's posture: the recognised pair (atom names in lexical order)
// and every atom's weight; null without atoms or a descriptor.
nlohmann::json PostureJson(const std::optional<Posture>& posture, const PostureAtoms* atoms) {
  if (!posture || !atoms) return nullptr;
  nlohmann::json weights = nlohmann::json::object();
  for (size_t k = 0; k < posture->weights.size(); ++k) {
    weights[atoms->names[k]] = std::round(posture->weights[k] * 1e4) / 1e4;
  }
  return {{"pair", {atoms->names[posture->pair[0]], atoms->names[posture->pair[1]]}}, {"weights", weights}};
}

// The pair the posture's weights alone give, as arm postures for the pose
// tracker's posture proposal (thesis 6.3.2). Not the pair that agrees with
// the pose tracker's rest state (PostureAtoms::pair_rest_state): the
// proposal is to bring the shape's own evidence to the filter. The atoms
// are named by the truth's posture labels (sequence_format/posture_labels.h);
// the lowest band ends at a hanging arm, about -60 deg. None when an atom
// has another name.
std::optional<PostureBands> PostureBandsOf(const Posture& posture, const PostureAtoms& atoms) {
  const std::vector<double> arm_weights(posture.weights.begin() + 1, posture.weights.end());
  const std::array<int, 2> pair =
      posture.weights[0] > 0 ? PairFromWeights(arm_weights, atoms) : std::array<int, 2>{0, 0};
  PostureBands bands;
  for (int i = 0; i < 2; ++i) {
    const std::string& name = atoms.names[pair[i]];
    if (name == kRestAtom) {
      bands[i] = {.rest = true};
      continue;
    }
    const auto band = std::find_if(kArmAtomBands.begin(), kArmAtomBands.end(),
                                   [&](const ArmAtomBand& b) { return b.name == name; });
    if (band == kArmAtomBands.end()) return std::nullopt;
    bands[i] = {.min_deg = std::max(band->min_deg, -60.0), .max_deg = band->max_deg};
  }
  return bands;
}

}  // namespace

std::shared_ptr<const RestClassifier> LoadRestClassifier(const TrackerSettings& settings) {
  if (settings.stage != TrackStage::kPose) return nullptr;
  const fs::path rest_path = settings.rest_model.empty() ? DefaultRestModelPath() : settings.rest_model;
  if (!settings.rest_model.empty() || fs::exists(rest_path)) {
    return std::make_shared<RestClassifier>(RestClassifier::Load(rest_path));
  }
  Log().warn("track: no rest-state model at {} (irbench train rest); rest stays null", rest_path.string());
  return nullptr;
}


namespace {

FrontEnd TrainTimed(const SequenceInput& input, const FrontEndOptions& options, double* ms) {
  const auto start = std::chrono::steady_clock::now();
  FrontEnd front_end = FrontEnd::Train(input, options);
  *ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return front_end;
}

}  // namespace

FrameTracker::FrameTracker(const SequenceInput& input,
                           const TrackerSettings& settings,
                           const FrontEndOptions& front_end_options,
                           std::shared_ptr<const RestClassifier> rest_classifier)
    : input_(input),
      nss_(settings.nss),
      front_end_(TrainTimed(input, front_end_options, &train_ms_)),
      health_(front_end_.camera_references(), front_end_options.health),
      last_health_(input.cameras().size(), CameraHealth::kOk),
      left_out_counts_(input.cameras().size()) {
  if (settings.stage == TrackStage::kPose) {
    pose_tracker_.emplace(input.cameras(), input.screens(), settings.pose);
    posture_proposal_ = settings.pose.p_posture > 0;
    if (rest_classifier) pose_tracker_->set_rest_classifier(rest_classifier);
    rest_classifier_ = std::move(rest_classifier);
    LoadMotionLabeler(settings);
  }
  const fs::path atoms = settings.posture_atoms.empty() ? DefaultPostureAtomsPath() : settings.posture_atoms;
  if (!settings.posture_atoms.empty() || fs::exists(atoms)) {
    posture_atoms_ = std::make_shared<PostureAtoms>(PostureAtoms::Load(atoms));
    posture_atoms_path_ = atoms;
    shape_options_ = posture_atoms_->descriptor;
  }
  const fs::path gestures = settings.gesture_models.empty() ? DefaultGestureModelsPath() : settings.gesture_models;
  if (!settings.gesture_models.empty() || (posture_atoms_ && fs::exists(gestures))) {
    if (!posture_atoms_) {
      throw InputError(gestures.string(), "", "gesture recognition needs posture atoms (--posture-atoms)");
    }
    gesture_models_ = std::make_shared<GestureModels>(GestureModels::Load(gestures));
    if (gesture_models_->atoms != posture_atoms_->names) {
      throw InputError(gestures.string(), "atoms", "were trained for other posture atoms than " +
                                                       posture_atoms_path_.string() + "'s");
    }
    gesture_models_path_ = gestures;
    gesture_recognizer_.emplace(gesture_models_, settings.gesture_model);
  }
}

void FrameTracker::LoadMotionLabeler(const TrackerSettings& settings) {
  if (settings.motion_model == MotionModelChoice::kNone) return;
  const MotionModelKind kind =
      settings.motion_model == MotionModelChoice::kCrf ? MotionModelKind::kCrf : MotionModelKind::kLdcrf;
  const fs::path path = settings.motion_labels.empty() ? DefaultMotionLabelModelPath(kind) : settings.motion_labels;
  if (settings.motion_labels.empty() && !fs::exists(path)) {
    Log().warn("track: no motion-label model at {} (irbench train motion-labels); motion stays null", path.string());
    return;
  }
  auto model = std::make_shared<MotionLabelModel>(MotionLabelModel::Load(path));
  if (model->kind != kind) {
    throw InputError(path.string(), "kind", std::string("is ") + MotionModelKindName(model->kind) +
                                                ", --motion-model asks for " + MotionModelKindName(kind));
  }
  motion_labels_path_ = path;
  motion_labeler_.emplace(std::move(model));
}

std::vector<MotionLabeler::Labels> FrameTracker::FinishMotion() {
  return motion_labeler_ ? motion_labeler_->Finish() : std::vector<MotionLabeler::Labels>{};
}

nlohmann::json FrameTracker::MotionJson(const MotionLabeler::Labels& labels) {
  if (!labels.arms) return nullptr;
  return {{"right", (*labels.arms)[0]}, {"left", (*labels.arms)[1]}};
}

FrameTracker::Step FrameTracker::Track(int f,
                                       std::vector<cv::Mat> images,
                                       const std::vector<std::string>& problems,
                                       double dt) {
  // Which cameras to leave out; a warning when a camera's state changes.
  const std::vector<CameraStatus> status = health_.Update(images);
  for (size_t c = 0; c < images.size(); ++c) {
    const CameraHealth h = status[c].health;
    const std::string& name = input_.cameras()[c].name;
    if (h != last_health_[c] && h == CameraHealth::kOk) {
      Log().warn("track: camera {} ok again from frame {}", name, f);
    } else if (h != last_health_[c]) {
      Log().warn("track: camera {} {} from frame {}{}{}", name, CameraHealthName(h), f,
                 problems[c].empty() ? "" : " (" + problems[c] + ")",
                 h == CameraHealth::kMissing || front_end_.options().health.leave_out ? ": left out" : "");
    } else if (!problems[c].empty()) {
      Log().debug("track: frame {} of camera {} skipped: {}", f, name, problems[c]);
    }
    last_health_[c] = h;
    // A missing frame is drawn black (silhouettes, overlays).
    if (images[c].empty()) images[c] = cv::Mat::zeros(input_.cameras()[c].height, input_.cameras()[c].width, CV_8U);
  }
  std::vector<bool> left_out(status.size());
  for (size_t c = 0; c < status.size(); ++c) {
    left_out[c] = status[c].health == CameraHealth::kMissing ||
                  (!status[c].usable() && front_end_.options().health.leave_out);
    if (left_out[c]) ++left_out_counts_[c][CameraHealthName(status[c].health)];
  }
  Step step;
  step.features = front_end_.Process(f, images, left_out);
  for (size_t c = 0; c < status.size(); ++c) {
    step.features.cameras[c].health = status[c].health;
    step.features.cameras[c].mean_level = status[c].mean_level;
  }
  if (pose_tracker_) step.pose = pose_tracker_->Step(step.features, dt);
  const auto shape_start = std::chrono::steady_clock::now();
  step.shape = Shape(step.features, step.pose, shape_options_);
  const auto shape_end = std::chrono::steady_clock::now();
  const double shape_ms = std::chrono::duration<double, std::milli>(shape_end - shape_start).count();
  if (step.shape && posture_atoms_) {
    // How many arms the rest-state classifier finds at rest, when it judged both.
    std::optional<int> arms_at_rest;
    if (step.pose && step.pose->tracking && step.pose->rest[0] && step.pose->rest[1]) {
      arms_at_rest = int{*step.pose->rest[0]} + int{*step.pose->rest[1]};
    }
    user_rest_.Update(step.shape->bins, arms_at_rest == 2);
    step.posture = DecomposePosture(step.shape->bins, user_rest_.Current(), *posture_atoms_, arms_at_rest);
  }
  // The posture proposal of the next frame-set's particles, when it is on.
  if (pose_tracker_ && posture_proposal_) {
    pose_tracker_->set_posture(step.posture && step.pose && step.pose->tracking
                                   ? PostureBandsOf(*step.posture, *posture_atoms_)
                                   : std::nullopt);
  }
  if (gesture_recognizer_) {
    std::optional<GestureObservation> observation;
    if (step.posture) {
      observation.emplace();
      observation->weights = Eigen::Map<const Eigen::VectorXd>(step.posture->weights.data(), step.posture->weights.size());
      observation->primary = step.posture->pair[1];
      observation->secondary = step.posture->pair[0];
    }
    // Both arms at rest by the rest-state classifier; where it has no
    // answer (the pose not tracked), by the recognised posture.
    const bool at_rest = step.pose ? BothArmsAtRest(step.pose->rest[0], step.pose->rest[1], observation)
                                   : BothArmsAtRest(std::nullopt, std::nullopt, observation);
    step.gesture = gesture_recognizer_->Update(f, observation, at_rest);
  }
  const auto recognition_end = std::chrono::steady_clock::now();
  const double recognition_ms = std::chrono::duration<double, std::milli>(recognition_end - shape_end).count();
  if (nss_ && step.features.voxels && step.features.placement) {
    // The person's front: the tracked body's yaw, else the screens' way (+y).
    const Eigen::Vector2d facing =
        step.pose && step.pose->tracking ? FacingDirection(step.pose->pose.dof[3]) : Eigen::Vector2d::UnitY();
    step.nss = ComputeNssSkeleton(*step.features.voxels, facing);
  }
  const double nss_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - recognition_end).count();
  nlohmann::json& line = step.features_line;
  line["frame"] = f;
  line["t"] = f / input_.fps();
  for (size_t c = 0; c < input_.cameras().size(); ++c) {
    line["cameras"][input_.cameras()[c].name] = CameraFeaturesJson(step.features, c);
  }
  AddHullFeatures(step.features, input_.cameras(), line);
  line["shape"] = ShapeJson(step.shape);
  if (nss_) line["nss"] = NssJson(step.nss);
  step.track_line = TrackLine(f, f / input_.fps(), step.features, step.pose, input_.cameras(), line);
  line["ms"] = StageMs(step.features, step.pose);
  line["ms"]["shape"] = shape_ms;
  line["ms"]["postures_gestures"] = recognition_ms;
  if (nss_) line["ms"]["nss"] = nss_ms;
  step.track_line["posture"] = PostureJson(step.posture, posture_atoms_.get());
  if (step.gesture) {
    step.track_line["gesture"] = {{"label", gesture_models_->gestures[step.gesture->gesture]},
                                  {"score", std::round(step.gesture->score * 1e3) / 1e3},
                                  {"start_frame", step.gesture->start_frame}};
  }
  if (motion_labeler_) {
    const auto motion_start = std::chrono::steady_clock::now();
    step.motion = motion_labeler_->Update(f, MotionObservationFromTrackLine(step.track_line, rest_classifier_.get()));
    line["ms"]["motion_labels"] =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - motion_start).count();
  }
  step.track_line["ms"] = line["ms"];
  step.images = std::move(images);
  return step;
}

}  // namespace irbench
