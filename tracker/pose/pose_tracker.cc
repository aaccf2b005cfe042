#include "tracker/pose/pose_tracker.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <limits>
#include <cmath>
#include <numeric>
#include <optional>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <utility>

#include "common/logging.h"
#include "tracker/pose/internal/median.h"

namespace irbench {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;
using pose_internal::Median;

double Millis(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - since).count();
}

}  // namespace

PoseTracker::PoseTracker(std::vector<Camera> cameras, std::vector<ScreenSurface> screens,
                         const PoseTrackerOptions& options)
    : cameras_(std::move(cameras)), screens_(std::move(screens)), options_(options), rng_(options.seed),
      root_offset_(options.root_offset_smoothing_s, options.root_offset_memory_s), calibration_(options) {
  options_.Check();
  for (const Camera& cam : cameras_) {
    projections_.push_back(ProjectionMatrix(cam));
    cv::Mat m1, m2;
    MakeUndistortMaps(cam, &m1, &m2);
    map1_.push_back(m1);
    map2_.push_back(m2);
  }
  // A camera whose image cuts off a person standing at the stage's centre
  // (aimed too high, too close) would keep every frame "partial": it is left
  // out of the in-view test, with a warning. (Its silhouette still counts:
  // the hull and the likelihood take what it sees.)
  for (const Camera& cam : cameras_) {
    holds_stage_.push_back(HoldsBox(cam, Vector3d::Zero(), kStageCheckHeightM, options_.view_margin_m));
  }
  if (std::none_of(holds_stage_.begin(), holds_stage_.end(), [](bool holds) { return holds; })) {
    // No camera holds the centre: the stage lies elsewhere; every camera decides.
    holds_stage_.assign(cameras_.size(), true);
  }
  for (size_t c = 0; c < cameras_.size(); ++c) {
    if (!holds_stage_[c]) {
      Log().warn("pose: camera '{}' does not hold a person standing at the stage's centre (a {:.1f} m box about (0, 0) "
                 "reaches outside its image): it is left out of the in-view test, which it would always fail",
                 cameras_[c].name, kStageCheckHeightM);
    }
  }
  // Users face the screen (thesis 1.2): the mean of the screens' centres.
  Vector2d sum = Vector2d::Zero();
  for (const ScreenSurface& s : screens_) sum += s.PointAt(s.Size() / 2).head<2>();
  if (!screens_.empty() && sum.norm() > 1e-6) facing_xy_ = (sum / screens_.size()).normalized();
}

double PoseTracker::Evaluate(const BodyPose& pose, const std::vector<SilhouetteView>& views,
                             std::vector<double>* overlaps) const {
  return Evaluate(shape_, pose, views, overlaps);
}

bool HoldsBox(const Camera& cam, const Eigen::Vector3d& root, double height_m, double margin_m) {
  for (double z : {0.05, 0.5 * height_m, height_m}) {
    for (double dx : {-margin_m, margin_m}) {
      for (double dy : {-margin_m, margin_m}) {
        const Vector3d p(root.x() + dx, root.y() + dy, z);
        const Vector3d p_in_cam = cam.cam_from_world * p;
        if (p_in_cam.z() <= 0.05) return false;
        const Eigen::Vector2d px = cam.ProjectInCamera(p_in_cam);
        if (!(px.x() >= 0 && px.y() >= 0 && px.x() <= cam.width - 1 && px.y() <= cam.height - 1)) return false;
      }
    }
  }
  return true;
}

bool PoseTracker::InView(const Eigen::Vector3d& root) const {
  for (size_t c = 0; c < cameras_.size(); ++c) {
    if (holds_stage_[c] && !HoldsBox(cameras_[c], root, shape_.height_m, options_.view_margin_m)) return false;
  }
  return true;
}

bool PoseTracker::FeetShowHeading() const {
  return options_.heading_from_feet && feet_toes_.norm() >= std::max(options_.feet_min_m, 1e-6);
}

Vector2d PoseTracker::Preferred() const {
  if (FeetShowHeading()) return feet_toes_.normalized();
  return facing_xy_;
}

bool PoseTracker::IsStep(const Eigen::Vector2d& velocity_xy) const {
  // A slow move that the feet, planted and clearly pointing, do not follow
  // is a step to the side or back (people shuffle, step back, sway while
  // they gesture), not a walk: the feet keep the heading. During a real
  // walk the feet's average is short (the floor layer alternates between
  // one foot's heel and the other's toes), so it does not veto the walk.
  if (!FeetShowHeading() || velocity_xy.norm() >= options_.step_max_speed_mps) return false;
  const double cos_angle = feet_toes_.normalized().dot(velocity_xy.normalized());
  return cos_angle < std::cos(options_.step_feet_angle_deg * M_PI / 180);
}

void PoseTracker::MeasureLegs(const FrameFeatures& features, double dt, PoseEstimate* out) {
  if (!out->tracking || !features.voxels) {
    root_offset_.Reset();
    return;
  }
  const Vector3d forward = out->body.frames[kLowerBody].linear() * Vector3d::UnitY();
  const auto legs =
      MeasureHullLegs(*features.voxels, out->body.joints[kModelRoot], forward, shape_.height_m, options_.hull_legs);
  const Vector3d root = root_offset_.Root(out->body.joints[kModelRoot], forward, legs, dt);
  if (options_.root_from_hull) out->body.joints[kModelRoot] = root;
  const double keep = std::exp(-dt / options_.feet_memory_s);
  feet_toes_ = keep * feet_toes_ + (1 - keep) * (legs && legs->toes ? *legs->toes : Vector2d::Zero());
}

double PoseTracker::HeadingPrior(const BodyPose& pose) const {
  auto away = [&](const Vector2d& dir) { return (1.0 - std::cos(pose.dof[kDofYaw] - YawFacing(dir))) / 2; };
  if (walking_) return -options_.walking_heading_prior * away(velocity_xy_.normalized());
  if (walk_memory_ > 0) {
    const Vector2d blend = walk_memory_ * walk_dir_ + (1 - walk_memory_) * Preferred();
    if (blend.norm() > 1e-3) return -options_.screen_heading_prior * away(blend.normalized());
  }
  return -options_.screen_heading_prior * away(Preferred());
}

double PoseTracker::Evaluate(const BodyShape& shape, const BodyPose& pose, const std::vector<SilhouetteView>& views,
                             std::vector<double>* overlaps) const {
  const PosedBody body = PoseBody(shape, pose);
  double log_likelihood = 0;
  if (overlaps) overlaps->assign(cameras_.size(), 0.0);
  for (size_t c = 0; c < cameras_.size(); ++c) {
    if (LeftOut(c)) {
      if (overlaps) (*overlaps)[c] = std::numeric_limits<double>::quiet_NaN();
      continue;
    }
    const double r = views[c].OverlapRatio(ProjectBody(cameras_[c], projections_[c], body));
    if (overlaps) (*overlaps)[c] = r;
    log_likelihood += options_.observation.sharpness * std::log(std::max(r, 0.01));
  }
  return log_likelihood;
}

bool PoseTracker::HeadSeenByAll(const PosedBody& body, const std::vector<SilhouetteView>& views) const {
  const Eigen::Vector4d head = body.joints[kModelHead].homogeneous();
  for (size_t c = 0; c < cameras_.size(); ++c) {
    if (LeftOut(c)) continue;
    const Vector3d p = projections_[c] * head;
    if (!(p.z() > 0)) return false;
    const cv::Mat& silhouette = views[c].ideal_silhouette();
    const int u = static_cast<int>(std::floor(p.x() / p.z() + 0.5)), v = static_cast<int>(std::floor(p.y() / p.z() + 0.5));
    if (u < 0 || v < 0 || u >= silhouette.cols || v >= silhouette.rows || silhouette.at<uint8_t>(v, u) == 0) return false;
  }
  return true;
}

void PoseTracker::Initialise(const FrameFeatures& features) {
  const BodyPlacement& place = *features.placement;
  shape_ = calibration_.Start(place.top_m);
  const Vector2d root = place.root.head<2>();
  const Vector2d to_centre = -root;
  // First seen half in view: entering, heading for the centre.
  walk_memory_ = 0;
  entering_ = false;
  if (!InView(place.root) && to_centre.norm() > 0.5) {
    walk_dir_ = to_centre.normalized();
    walk_memory_ = 1;
    entering_ = true;
  }
  // A user standing in view at once: the feet tell which way they face
  // (averaged from here on by MeasureLegs). Without this first reading the
  // mocap suite's arms were 17.50 cm against 17.15, CMU 141_16's shoulders
  // 10.1 against 4.0 cm.
  feet_toes_ = Vector2d::Zero();
  root_offset_.Reset();
  if (features.voxels && !entering_) {
    const auto legs = MeasureHullLegs(*features.voxels, place.root, Vector3d(facing_xy_.x(), facing_xy_.y(), 0),
                                      shape_.height_m, options_.hull_legs);
    if (legs && legs->toes) feet_toes_ = *legs->toes;
  }
  const Vector2d to_screen = Preferred();
  std::normal_distribution<double> yaw_noise(0.0, 0.3), pos_noise(0.0, 0.03);
  particles_.clear();
  // Half face the screen (or where the feet point); half face the stage's
  // centre, where a user who has just walked in is heading.
  const double yaw_centre = to_centre.norm() > 0.5 ? YawFacing(to_centre.normalized()) : YawFacing(to_screen);
  for (int i = 0; i < options_.particles; ++i) {
    const double yaw = (i % 4 < 2 ? YawFacing(to_screen) : yaw_centre) + yaw_noise(rng_);
    BodyPose p = (i % 2 == 0) ? StandingPose(shape_, root, yaw) : ScarecrowPose(shape_, root, yaw);
    p.dof[kDofX] += pos_noise(rng_);
    p.dof[kDofY] += pos_noise(rng_);
    particles_.push_back(p);
  }
  previous_ = particles_;
}

void PoseTracker::Scatter() {
  std::uniform_real_distribution<double> pos(-1.5, 1.5), yaw(-M_PI, M_PI), zen(0.0, 2.5), az(-M_PI, M_PI);
  for (BodyPose& p : particles_) {
    p = StandingPose(shape_, Vector2d(pos(rng_), pos(rng_)), yaw(rng_));
    for (int sh : {kDofRightShoulderAzimuth, kDofLeftShoulderAzimuth}) {
      p.dof[sh] = az(rng_);
      p.dof[sh + 1] = zen(rng_);
    }
    ClampToJointLimits(&p);
  }
  previous_ = particles_;
}

void PoseTracker::MakeViews(const FrameFeatures& features, std::vector<SilhouetteView>* views,
                            std::vector<IcpView>* icp_views) const {
  for (size_t c = 0; c < cameras_.size(); ++c) {
    views->emplace_back(cameras_[c], features.cameras[c].silhouette, map1_[c], map2_[c], options_.observation.scale);
    if (options_.refine_fraction > 0 && options_.icp.iterations > 0 && !LeftOut(c)) {
      icp_views->push_back({cameras_[c], projections_[c], OutlinePolygons(views->back().ideal_silhouette())});
    }
  }
}

void PoseTracker::UpdateWalking(const Eigen::Vector2d& root_xy, double dt) {
  // The hull's ground velocity over the last half second (single frames are
  // too noisy: a centimetre of jitter per frame reads as 0.4 m/s): a walking
  // user's heading.
  if (!active_) recent_roots_.clear();
  recent_roots_.push_back(root_xy);
  const size_t window = static_cast<size_t>(std::max(10.0, std::round(0.5 / std::max(dt, 1e-3))));
  while (recent_roots_.size() > window + 1) recent_roots_.pop_front();
  velocity_xy_.setZero();
  walking_ = false;
  if (recent_roots_.size() == window + 1) {
    // Walking: the median of the window's first five roots to the median of
    // its last five (the hull's root jumps while a user is half in view, and
    // when a shadow or an arm joins the legs' voxels).
    auto median_of = [&](size_t from) {
      std::vector<double> xs, ys;
      for (size_t i = from; i < from + 5; ++i) {
        xs.push_back(recent_roots_[i].x());
        ys.push_back(recent_roots_[i].y());
      }
      return Vector2d(Median(xs), Median(ys));
    };
    const double span = (window - 4) * dt;
    velocity_xy_ = (median_of(recent_roots_.size() - 5) - median_of(0)) / span;
    // A walk is steady: the root advances along the walking direction over
    // at least three quarters of the window's 3-frame steps (a root that
    // jumps for a few frames — a shadow or a raised arm joining the legs'
    // voxels — does not).
    bool steady = false;
    if (velocity_xy_.norm() > options_.walking_speed_mps) {
      const Vector2d dir = velocity_xy_.normalized();
      int ahead = 0, steps = 0;
      for (size_t i = 0; i + 3 < recent_roots_.size(); ++i, ++steps) {
        ahead += (recent_roots_[i + 3] - recent_roots_[i]).dot(dir) > 0.01;
      }
      steady = steps > 0 && ahead >= 0.75 * steps;
      if (steady && IsStep(velocity_xy_)) steady = false;
    }
    moving_frames_ = steady ? moving_frames_ + 1 : 0;
    // A move against the way the estimate faces is taken for a step back
    // until it has lasted step_back_max_s, once the heading has settled.
    int needed = 2;
    if (steady && last_yaw_ && tracked_s_ >= options_.heading_settled_s &&
        FacingDirection(*last_yaw_).dot(velocity_xy_) < 0) {
      needed = std::max(needed, static_cast<int>(std::lround(options_.step_back_max_s / std::max(dt, 1e-3))));
    }
    walking_ = moving_frames_ >= needed;
  } else {
    moving_frames_ = 0;
  }
  if (walking_) {
    walk_dir_ = velocity_xy_.normalized();
    walk_memory_ = 1;
  } else if (active_) {
    walk_memory_ = std::max(0.0, walk_memory_ - dt / std::max(options_.walk_memory_s, 1e-6));
  }
  if (walking_ || walk_memory_ < 0.5) entering_ = false;
}

std::vector<double> PoseTracker::ReadAxisPoints(const FrameFeatures& features) {
  // What the proposals read of the 3D axis points, once per frame.
  arm_chains_ = ChainArmPoints(features.axis3d);
  torso_xy_.clear();
  std::vector<double> arm_diameters;  // this frame's, metres
  for (const AxisPoint3d& a : features.axis3d) {
    if (a.part == BodyPart::kTorso) torso_xy_.push_back(a.p_in_world.head<2>());
    if (a.part == BodyPart::kArm && a.diameter_m > 0) arm_diameters.push_back(a.diameter_m);
  }
  return arm_diameters;
}

std::vector<BodyPose> PoseTracker::ProposeParticles(const FrameFeatures& features, double dt) {
  std::vector<BodyPose> proposed;
  if (!active_) {
    Initialise(features);
    active_ = true;
    proposed = particles_;
  } else {
    if (!calibration_.height_measured() && InView(features.placement->root)) {
      // Until the height is measured (Calibrate), the model follows the
      // hull's top (BodyCalibration::MatchHullTop).
      if (const std::optional<double> ratio = calibration_.MatchHullTop(features.placement->top_m, &shape_)) {
        for (BodyPose& p : particles_) p.dof[kDofZ] *= *ratio;
        for (BodyPose& p : previous_) p.dof[kDofZ] *= *ratio;
      }
    }
    const ProposalContext context{.options = options_,
                                  .shape = shape_,
                                  .features = features,
                                  .arm_chains = arm_chains_,
                                  .torso_xy = torso_xy_,
                                  .facing_xy = Preferred(),
                                  .velocity_xy = velocity_xy_,
                                  .walk_dir = walk_dir_,
                                  .walking = walking_,
                                  .entering = entering_,
                                  .lost = lost_,
                                  .posture = posture_,
                                  .floor_gap_m = floor_gap_m_,
                                  .extra_rise_m = ExtraRise()};
    for (size_t i = 0; i < particles_.size(); ++i) {
      proposed.push_back(ProposeParticle(particles_[i], previous_[i], dt, context, rng_));
    }
  }
  return proposed;
}

bool PoseTracker::EstimateFromBest(const std::vector<BodyPose>& proposed, int best, const FrameFeatures& features,
                                   const std::vector<SilhouetteView>& views, PoseEstimate* out) const {
  out->log_likelihood = Evaluate(proposed[best], views, &out->overlap);
  double sum = 0;
  int seen = 0;
  for (double r : out->overlap) {
    if (!std::isnan(r)) sum += r, ++seen;
  }
  const double mean_overlap = seen > 0 ? sum / seen : 0.0;
  const bool fits = mean_overlap >= options_.min_overlap;
  out->in_view = InView(features.placement->root);
  out->tracking = fits && out->in_view;
  out->pose = proposed[best];
  return fits;
}

void PoseTracker::Calibrate(const FrameFeatures& features, const std::vector<SilhouetteView>& views,
                            const std::vector<double>& arm_diameters, std::vector<BodyPose>* proposed,
                            PoseEstimate* out) {
  // Height and girth (thesis 6.1.2; BodyCalibration::MeasureHeightAndGirth):
  // the particles keep their angles and move their waist heights with the
  // scale.
  const BodyCalibration::ShapeScore score = [&](const BodyShape& shape, const BodyPose& pose) {
    return Evaluate(shape, pose, views, nullptr);
  };
  // Without a voxel hull (the front end's placement alone) the feet are
  // taken to be on the floor; they are looked for only in a frame that
  // could be measured (with a camera dead all take, not every frame).
  const bool all_views = features.UsableCameras() == static_cast<int>(features.cameras.size());
  const bool feet_on_floor = !out->tracking || !calibration_.takes_height_sample(all_views) || !features.voxels ||
                             FeetOnFloor(*features.voxels, PoseBody(shape_, out->pose).joints[kModelRoot],
                                         shape_.height_m, options_.hull_legs);
  if (const std::optional<double> ratio = calibration_.MeasureHeightAndGirth(
          out->tracking, out->pose, features.placement->top_m, feet_on_floor, all_views, score, &shape_)) {
    for (BodyPose& p : *proposed) p.dof[kDofZ] *= *ratio;
    for (BodyPose& p : particles_) p.dof[kDofZ] *= *ratio;
    out->pose.dof[kDofZ] *= *ratio;
  }
  // Arm thickness (BodyCalibration::MeasureArmThickness).
  calibration_.MeasureArmThickness(out->tracking, arm_diameters, &shape_);
  // Shoulder width (thesis 6.1.1; BodyCalibration::MeasureShoulderWidth).
  // Once its samples are in, the arms' points are not split by side for it.
  if (out->tracking && options_.configure_shoulders && calibration_.measuring_shoulders() && arm_chains_.count > 0) {
    const PosedBody body = PoseBody(shape_, out->pose);
    calibration_.MeasureShoulderWidth(
        out->tracking, body,
        ArmPointsBySide(arm_chains_.points, arm_chains_.chain, arm_chains_.count,
                        body.joints[kModelRightShoulder], body.joints[kModelLeftShoulder]),
        &shape_);
  }
}

bool PoseTracker::RestVote(const std::vector<std::optional<PosedBody>>& voters, const std::vector<double>& vote_weight,
                           bool left) const {
  const int n = static_cast<int>(voters.size());
  double rest_weight = 0, total_weight = 0;
  for (int i = 0; i < n; ++i) {
    if (!voters[i]) continue;
    const auto& j = voters[i]->joints;
    const bool r = rest_->AtRest(RestFeatures(
        j[kModelWaist], j[kModelNeck], j[kModelRightShoulder], j[kModelLeftShoulder],
        j[left ? kModelLeftElbow : kModelRightElbow], j[left ? kModelLeftWrist : kModelRightWrist],
        shape_.height_m, left));
    rest_weight += r ? vote_weight[i] : 0.0;
    total_weight += vote_weight[i];
  }
  return rest_weight > 0.5 * total_weight;
}

namespace {

// The hanging arm's forearms (elbow azimuth, zenith): straight or bent
// forward, for the rest test and the arm forced down ...
constexpr std::pair<double, double> kHangingForearms[] = {{M_PI / 2, 0.0}, {M_PI / 2, 0.4}, {M_PI / 2, 0.8},
                                                          {M_PI / 2, 1.1}};
// ... and, once the arm is found at rest, held further forward, and forward
// and across the belly (PoseTrackerOptions::rest_held_forearms).
constexpr std::pair<double, double> kHeldForearms[] = {{M_PI / 2, 1.4},      {M_PI / 2, 1.7},
                                                       {3 * M_PI / 4, 0.8}, {3 * M_PI / 4, 1.1},
                                                       {3 * M_PI / 4, 1.4}, {3 * M_PI / 4, 1.7}};

}  // namespace

bool PoseTracker::BestHangingArm(const BodyPose& pose, bool left, const std::vector<SilhouetteView>& views,
                                 std::span<const std::pair<double, double>> forearms, BodyPose* down,
                                 double* ll) const {
  // Forced down: the hanging pose the silhouettes like best, out to the
  // side, a little forward or back, the forearm straight or bent forward.
  // People seldom hang their arms dead straight; against a single
  // straight pose a bent hanging arm lost enough overlap to fail the
  // likelihood-ratio test. Real motion swings and holds its hanging arms
  // further than the library's: a walking arm back or forward, a wave's
  // other arm 20 degrees out (CMU 141_16, 05_01: arms 12.4 -> 6.8 and
  // 7.7 -> 4.5 cm with these candidates; docs/tracker.md).
  const int sh = left ? kDofLeftShoulderAzimuth : kDofRightShoulderAzimuth;
  const int el = left ? kDofLeftElbowAzimuth : kDofRightElbowAzimuth;
  static constexpr std::pair<double, double> kShoulders[] = {  // azimuth, zenith
      {0.0, 0.1}, {M_PI / 2, 0.15}, {M_PI / 2, 0.35}, {-M_PI / 2, 0.25}, {0.0, 0.35}};
  bool found = false;
  for (const auto& [shoulder_azimuth, shoulder_zenith] : kShoulders) {
    for (const auto& [elbow_azimuth, elbow_zenith] : forearms) {
      BodyPose candidate = pose;
      candidate.dof[sh] = shoulder_azimuth;
      candidate.dof[sh + 1] = shoulder_zenith;
      candidate.dof[sh + 2] = 0.0;
      candidate.dof[el] = elbow_azimuth;
      candidate.dof[el + 1] = elbow_zenith;
      const double candidate_ll = Evaluate(candidate, views, nullptr);
      if (candidate_ll > *ll) {
        *ll = candidate_ll;
        *down = candidate;
        found = true;
      }
    }
  }
  return found;
}

void PoseTracker::DecideRest(const std::vector<BodyPose>& proposed, const std::vector<double>& log_likelihood,
                             int best, const std::vector<SilhouetteView>& views, double dt, PoseEstimate* out) {
  // Thesis 6.4: an arm at rest is forced down. The SVM's part of the
  // decision is a vote of the particles, weighted by their likelihood
  // tempered tenfold: an arm against the torso is poorly determined, and
  // the best particle alone flickers between nearby poses. Besides it, an
  // arm the 3D axis points show apart from the body is judged by their
  // angle, and one they do not show by the likelihood-ratio test
  // (PoseTrackerOptions).
  const int n = static_cast<int>(proposed.size());
  std::vector<double> vote_weight(n);
  std::vector<std::optional<PosedBody>> voters(n);  // posed once, for both arms
  for (int i = 0; i < n; ++i) {
    vote_weight[i] = std::exp((log_likelihood[i] - log_likelihood[best]) / 10.0);
    if (vote_weight[i] >= 1e-3) voters[i] = PoseBody(shape_, proposed[i]);
  }
  // The estimate's log-likelihood for the likelihood-ratio test, evaluated
  // when first needed and kept up to date when an arm is forced down.
  std::optional<double> estimate_ll;
  const auto arm_points = ArmPointsBySide(arm_chains_.points, arm_chains_.chain, arm_chains_.count,
                                          out->body.joints[kModelRightShoulder], out->body.joints[kModelLeftShoulder]);
  for (int side = 0; side < 2; ++side) {
    const bool left = side == 1;
    bool at_rest = RestVote(voters, vote_weight, left);
    // An arm the 3D axis points show apart from the body is where they
    // are: at rest when they hang within rest_seen_max_angle_deg of
    // straight down. Only an arm they do not show (against the torso, or
    // in front of it in every view) is left to the likelihood-ratio test,
    // which would take an arm just lifting off the side for one still
    // hanging; and not one just seen lifted, which has left the
    // silhouettes rather than dropped to the side unseen.
    const Vector3d shoulder = out->body.joints[left ? kModelLeftShoulder : kModelRightShoulder];
    const std::optional<Vector3d> farthest = FarthestArmPoint(arm_points[side], shoulder);
    if (farthest) {
      const double angle = std::acos(std::clamp(-(*farthest - shoulder).normalized().z(), -1.0, 1.0)) * 180 / M_PI;
      at_rest = at_rest || angle < options_.rest_seen_max_angle_deg;
      lifted_age_s_[side] = angle >= options_.rest_lifted_angle_deg ? 0.0 : kNever;
    } else {
      lifted_age_s_[side] += dt;
    }
    const bool ratio_test = !farthest && options_.rest_max_log_overlap_loss > 0 &&
                            lifted_age_s_[side] > options_.rest_lifted_memory_s;
    if (!at_rest && !ratio_test) {
      out->rest[side] = false;
      continue;
    }
    double down_ll = -std::numeric_limits<double>::infinity();
    BodyPose down = out->pose;
    BestHangingArm(out->pose, left, views, kHangingForearms, &down, &down_ll);
    if (!at_rest) {
      // The likelihood-ratio test against the estimate as it stands (the
      // other arm perhaps forced down).
      if (!estimate_ll) estimate_ll = Evaluate(out->pose, views, nullptr);
      at_rest = (*estimate_ll - down_ll) / options_.observation.sharpness < options_.rest_max_log_overlap_loss;
    }
    out->rest[side] = at_rest;
    if (at_rest) {
      if (options_.rest_held_forearms) {
        // A held forearm must explain the silhouettes better by a margin.
        double held_ll = down_ll + options_.rest_held_min_gain * options_.observation.sharpness;
        if (BestHangingArm(out->pose, left, views, kHeldForearms, &down, &held_ll)) down_ll = held_ll;
      }
      out->pose = down;
      estimate_ll = down_ll;
    }
  }
  out->body = PoseBody(shape_, out->pose);
}

void PoseTracker::HeadAndPointing(const FrameFeatures& features, const std::vector<SilhouetteView>& views,
                                  PoseEstimate* out) const {
  if (out->tracking && options_.head_from_hull && features.voxels && HeadSeenByAll(out->body, views)) {
    // The head centre where the hull shows it (pointing.h): the pointing
    // rays' origin and the head joint.
    const auto head = HullHeadCentre(*features.voxels, out->body.joints[kModelHead],
                                     out->body.frames[kUpperBody].linear() * Vector3d::UnitY(), shape_.height_m,
                                     options_.hull_head);
    if (head) out->body.joints[kModelHead] = *head;
  }
  if (out->tracking) {
    if (!out->rest[0].value_or(false)) {
      out->pointing[0] = Pointing(out->body.joints[kModelHead], out->body.joints[kModelRightHandTip], screens_);
    }
    if (!out->rest[1].value_or(false)) {
      out->pointing[1] = Pointing(out->body.joints[kModelHead], out->body.joints[kModelLeftHandTip], screens_);
    }
  }
}

PoseEstimate PoseTracker::Step(const FrameFeatures& features, double dt) {
  const auto start = std::chrono::steady_clock::now();
  PoseEstimate out;
  left_out_ = features.left_out;
  if (!features.placement || features.cameras.size() != cameras_.size()) {
    active_ = false;
    last_yaw_.reset();
    last_head_.reset();
    tracked_s_ = 0;
    lost_ = false;
    lifted_age_s_ = {kNever, kNever};
    out.ms_total = Millis(start);
    return out;
  }
  std::vector<SilhouetteView> views;
  std::vector<IcpView> icp_views;
  MakeViews(features, &views, &icp_views);
  UpdateWalking(features.placement->root.head<2>(), dt);
  const std::vector<double> arm_diameters = ReadAxisPoints(features);
  // Off the floor: the hull's lowest part more than a few voxels up (the
  // floor layer of a standing user's hull starts at 0). Only for a user
  // whole in every view: one walking off the stage loses the feet from the
  // hull first.
  floor_gap_m_ = 0;
  if (features.voxels && InView(features.placement->root)) {
    const double gap = FloorGap(*features.voxels, features.placement->root, shape_.height_m, options_.hull_legs);
    if (gap >= options_.min_floor_gap_m) floor_gap_m_ = gap;
  }
  // On tiptoe: the hull's column over the last head stands above the
  // user's height.
  tiptoe_m_ = 0;
  if (options_.max_tiptoe_m > 0 && features.voxels && last_head_ && InView(features.placement->root)) {
    const std::optional<double> top =
        HullColumnTop(*features.voxels, last_head_->head<2>(), last_head_->z(), options_.tiptoe_radius_m);
    if (top) tiptoe_m_ = std::clamp(*top - shape_.height_m, 0.0, options_.max_tiptoe_m);
  }
  std::vector<BodyPose> proposed = ProposeParticles(features, dt);

  // The particle filter (particle_filter.h): weights (thesis 6.3.1), then the
  // refine-prediction (6.3.3): 2D-3D ICP on a random subset; a refined
  // particle replaces its original when it explains the silhouettes better.
  const PoseScore score = [&](const BodyPose& pose) { return Evaluate(pose, views, nullptr) + HeadingPrior(pose); };
  const auto t_obs = std::chrono::steady_clock::now();
  std::vector<double> log_likelihood = WeighParticles(proposed, score);
  out.ms_observation = Millis(t_obs);
  const auto t_refine = std::chrono::steady_clock::now();
  RefineParticles(shape_, icp_views, options_, score, rng_, &proposed, &log_likelihood, ExtraRise());
  out.ms_refine = Millis(t_refine);

  const int best = BestParticle(log_likelihood);
  const bool fits = EstimateFromBest(proposed, best, features, views, &out);
  Calibrate(features, views, arm_diameters, &proposed, &out);
  out.shape = shape_;
  out.body = PoseBody(shape_, out.pose);
  if (!out.tracking) lifted_age_s_ = {kNever, kNever};
  last_yaw_ = out.tracking ? std::optional<double>(out.pose.dof[kDofYaw]) : std::nullopt;
  tracked_s_ = out.tracking ? tracked_s_ + dt : 0;
  if (out.tracking && rest_ && !rest_->empty()) DecideRest(proposed, log_likelihood, best, views, dt, &out);
  MeasureLegs(features, dt, &out);
  HeadAndPointing(features, views, &out);
  last_head_ = out.tracking ? std::optional<Eigen::Vector3d>(out.body.joints[kModelHead]) : std::nullopt;

  // Resampling (systematic), carrying each particle's previous state along
  // for the velocity.
  ResampleSystematic(proposed, log_likelihood, log_likelihood[best], rng_, &particles_, &previous_);
  lost_ = !fits;
  out.ms_total = Millis(start);
  return out;
}

}  // namespace irbench
