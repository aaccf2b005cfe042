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

namespace irbench {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;

bool IsAngleDof(int d) { return d >= kDofYaw; }

double Millis(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - since).count();
}

double Median(std::vector<double> v) {
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

}  // namespace

void PoseTrackerOptions::Check() const {
  if (particles < 1) throw std::invalid_argument("pose.particles must be at least 1");
  observation.Check();
  icp.Check();
  for (double p : {p_random_walk, p_body_position, p_arm_direction, p_default_pose}) {
    if (!(p >= 0)) throw std::invalid_argument("pose proposal probabilities must be non-negative");
  }
  if (!(p_flip >= 0 && p_flip <= 1)) throw std::invalid_argument("pose.p_flip must be in [0, 1]");
  if (!(p_turn >= 0 && p_flip + p_turn <= 1)) throw std::invalid_argument("pose.p_turn must be in [0, 1 - p_flip]");
  if (!(p_random_walk + p_body_position + p_arm_direction + p_default_pose > 0)) {
    throw std::invalid_argument("pose proposal probabilities must not all be zero");
  }
  for (double s : {sigma_position_m, sigma_yaw_rad, sigma_torso_rad, sigma_arm_rad, max_step_rad, max_step_m}) {
    if (!(s >= 0)) throw std::invalid_argument("pose noise and caps must be non-negative");
  }
  if (!(velocity_damping >= 0 && velocity_damping <= 1)) {
    throw std::invalid_argument("pose.velocity_damping must be in [0, 1]");
  }
  if (!(refine_fraction >= 0 && refine_fraction <= 1)) {
    throw std::invalid_argument("pose.refine_fraction must be in [0, 1]");
  }
  if (!(min_overlap >= 0 && min_overlap <= 1)) throw std::invalid_argument("pose.min_overlap must be in [0, 1]");
  if (!(rest_max_log_overlap_loss >= 0)) throw std::invalid_argument("pose.rest_max_log_overlap_loss must be non-negative");
  if (!(max_rise_m >= 0)) throw std::invalid_argument("pose.max_rise_m must be non-negative");
  if (!(rest_seen_max_angle_deg >= 0 && rest_seen_max_angle_deg <= 180)) {
    throw std::invalid_argument("pose.rest_seen_max_angle_deg must be in [0, 180]");
  }
  if (!(rest_lifted_angle_deg >= 0 && rest_lifted_angle_deg <= 180)) {
    throw std::invalid_argument("pose.rest_lifted_angle_deg must be in [0, 180]");
  }
  if (!(rest_lifted_memory_s >= 0)) throw std::invalid_argument("pose.rest_lifted_memory_s must be non-negative");
  if (rest_lifted_angle_deg < rest_seen_max_angle_deg) {
    throw std::invalid_argument("pose.rest_lifted_angle_deg must be at least pose.rest_seen_max_angle_deg");
  }
  hull_head.Check();
  if (height_frames < 1) throw std::invalid_argument("pose.height_frames must be at least 1");
  if (arm_thickness_frames < 0) throw std::invalid_argument("pose.arm_thickness_frames must be non-negative");
  if (arm_thickness_min_points < 1) throw std::invalid_argument("pose.arm_thickness_min_points must be at least 1");
  if (!(arm_reference_diameter > 0)) throw std::invalid_argument("pose.arm_reference_diameter must be positive");
  if (!(max_arm_thickness >= 1)) throw std::invalid_argument("pose.max_arm_thickness must be at least 1");
  if (!(walk_memory_s >= 0)) throw std::invalid_argument("pose.walk_memory_s must be non-negative");
}

PoseTracker::PoseTracker(std::vector<Camera> cameras, std::vector<ScreenSurface> screens,
                         const PoseTrackerOptions& options)
    : cameras_(std::move(cameras)), screens_(std::move(screens)), options_(options), rng_(options.seed) {
  options_.Check();
  for (const Camera& cam : cameras_) {
    projections_.push_back(ProjectionMatrix(cam));
    cv::Mat m1, m2;
    MakeUndistortMaps(cam, &m1, &m2);
    map1_.push_back(m1);
    map2_.push_back(m2);
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

bool PoseTracker::InView(const Eigen::Vector3d& root) const {
  const double top = shape_.height_m;
  for (const Camera& cam : cameras_) {
    for (double z : {0.05, 0.5 * top, top}) {
      for (double dx : {-options_.view_margin_m, options_.view_margin_m}) {
        for (double dy : {-options_.view_margin_m, options_.view_margin_m}) {
          const Vector3d p(root.x() + dx, root.y() + dy, z);
          if ((cam.cam_from_world * p).z() <= 0.05) return false;
          const Eigen::Vector2d px = cam.Project(p);
          if (!(px.x() >= 0 && px.y() >= 0 && px.x() <= cam.width - 1 && px.y() <= cam.height - 1)) return false;
        }
      }
    }
  }
  return true;
}

double PoseTracker::HeadingPrior(const BodyPose& pose) const {
  auto away = [&](const Vector2d& dir) { return (1.0 - std::cos(pose.dof[kDofYaw] - YawFacing(dir))) / 2; };
  if (walking_) return -options_.walking_heading_prior * away(velocity_xy_.normalized());
  if (walk_memory_ > 0) {
    const Vector2d blend = walk_memory_ * walk_dir_ + (1 - walk_memory_) * facing_xy_;
    if (blend.norm() > 1e-3) return -options_.screen_heading_prior * away(blend.normalized());
  }
  return -options_.screen_heading_prior * away(facing_xy_);
}

double PoseTracker::Evaluate(const BodyShape& shape, const BodyPose& pose, const std::vector<SilhouetteView>& views,
                             std::vector<double>* overlaps) const {
  const PosedBody body = PoseBody(shape, pose);
  double log_likelihood = 0;
  if (overlaps) overlaps->assign(cameras_.size(), 0.0);
  for (size_t c = 0; c < cameras_.size(); ++c) {
    const double r = views[c].OverlapRatio(ProjectBody(cameras_[c], projections_[c], body));
    if (overlaps) (*overlaps)[c] = r;
    log_likelihood += options_.observation.sharpness * std::log(std::max(r, 0.01));
  }
  return log_likelihood;
}

bool PoseTracker::HeadSeenByAll(const PosedBody& body, const std::vector<SilhouetteView>& views) const {
  const Eigen::Vector4d head = body.joints[kModelHead].homogeneous();
  for (size_t c = 0; c < cameras_.size(); ++c) {
    const Vector3d p = projections_[c] * head;
    if (!(p.z() > 0)) return false;
    const cv::Mat& silhouette = views[c].ideal_silhouette();
    const int u = static_cast<int>(std::floor(p.x() / p.z() + 0.5)), v = static_cast<int>(std::floor(p.y() / p.z() + 0.5));
    if (u < 0 || v < 0 || u >= silhouette.cols || v >= silhouette.rows || silhouette.at<uint8_t>(v, u) == 0) return false;
  }
  return true;
}

namespace {

// Places the body so that its root lands on `root_xy`.
void PlaceRoot(const BodyShape& shape, BodyPose* pose, const Vector2d& root_xy) {
  const PosedBody body = PoseBody(shape, *pose);
  const Vector2d offset = root_xy - body.joints[kModelRoot].head<2>();
  pose->dof[kDofX] += offset.x();
  pose->dof[kDofY] += offset.y();
}

}  // namespace

void PoseTracker::Initialise(const FrameFeatures& features) {
  const BodyPlacement& place = *features.placement;
  heights_.clear();
  girths_.clear();
  arm_diameters_.clear();
  arm_frames_ = 0;
  arm_diameter_m_ = 0;
  shape_ = ShapeFor(std::clamp(place.top_m, 1.2, 2.2), 1.0);
  const Vector2d root = place.root.head<2>();
  Vector2d to_screen = facing_xy_;
  std::normal_distribution<double> yaw_noise(0.0, 0.3), pos_noise(0.0, 0.03);
  particles_.clear();
  // Half face the screen; half face the stage's centre, where a user who
  // has just walked in is heading.
  const Vector2d to_centre = -root;
  const double yaw_centre = to_centre.norm() > 0.5 ? YawFacing(to_centre.normalized()) : YawFacing(to_screen);
  // First seen half in view: entering, heading for the centre.
  walk_memory_ = 0;
  entering_ = false;
  if (!InView(place.root) && to_centre.norm() > 0.5) {
    walk_dir_ = to_centre.normalized();
    walk_memory_ = 1;
    entering_ = true;
  }
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

// The 3D arm axis points split into chains (single linkage within
// `link_m`), one per seen arm; once per frame.
PoseTracker::ArmChains PoseTracker::ChainArmPoints(const std::vector<AxisPoint3d>& axis3d, double link_m) {
  ArmChains out;
  for (const AxisPoint3d& a : axis3d) {
    if (a.part == BodyPart::kArm) out.points.push_back(a.p_in_world);
  }
  const int n = static_cast<int>(out.points.size());
  out.chain.assign(n, -1);
  for (int seed = 0; seed < n; ++seed) {
    if (out.chain[seed] >= 0) continue;
    std::vector<int> stack = {seed};
    out.chain[seed] = out.count;
    while (!stack.empty()) {
      const int i = stack.back();
      stack.pop_back();
      for (int j = 0; j < n; ++j) {
        if (out.chain[j] < 0 && (out.points[i] - out.points[j]).norm() < link_m) {
          out.chain[j] = out.count;
          stack.push_back(j);
        }
      }
    }
    ++out.count;
  }
  return out;
}

namespace {

// Each chain belongs to the shoulder nearest its nearest point, so an arm
// reaching across the body stays with the shoulder it starts from.
std::array<std::vector<Vector3d>, 2> ArmPointsBySide(const std::vector<Vector3d>& points, const std::vector<int>& chain,
                                                     int chains, const Vector3d& right_shoulder,
                                                     const Vector3d& left_shoulder) {
  const int n = static_cast<int>(points.size());
  std::array<std::vector<Vector3d>, 2> out;
  for (int c = 0; c < chains; ++c) {
    double best_right = 1e9, best_left = 1e9;
    for (int i = 0; i < n; ++i) {
      if (chain[i] != c) continue;
      best_right = std::min(best_right, (points[i] - right_shoulder).norm());
      best_left = std::min(best_left, (points[i] - left_shoulder).norm());
    }
    const int side = best_right <= best_left ? 0 : 1;
    for (int i = 0; i < n; ++i) {
      if (chain[i] == c) out[side].push_back(points[i]);
    }
  }
  return out;
}

// Arm axis points farther than this from the shoulder show the arm apart
// from the body.
constexpr double kArmApartM = 0.15;

// The arm point farthest from the shoulder, if one lies beyond kArmApartM.
std::optional<Vector3d> FarthestArmPoint(const std::vector<Vector3d>& points, const Vector3d& shoulder) {
  std::optional<Vector3d> farthest;
  double farthest_d = kArmApartM;
  for (const Vector3d& p : points) {
    const double d = (p - shoulder).norm();
    if (d > farthest_d) {
      farthest_d = d;
      farthest = p;
    }
  }
  return farthest;
}

}  // namespace

BodyPose PoseTracker::ArmDirectionProposal(BodyPose pose, const FrameFeatures& features) {
  const PosedBody body = PoseBody(shape_, pose);
  std::normal_distribution<double> jitter(0.0, 0.05);
  const auto by_side = ArmPointsBySide(arm_chains_.points, arm_chains_.chain, arm_chains_.count,
                                       body.frames[kRightUpperArm].translation(),
                                       body.frames[kLeftUpperArm].translation());
  // Half the proposals set both arms, the rest one arm (either side alike):
  // the other arm keeps its pose, so that a raised arm the axis points miss
  // this frame is not forced down while the seen one is placed.
  std::uniform_int_distribution<int> which(0, 3);
  const int only = which(rng_);  // 0, 1: both arms; 2: right only; 3: left only
  std::uniform_real_distribution<double> coin(0.0, 1.0);
  for (int arm : {kRightUpperArm, kLeftUpperArm}) {
    if ((only == 2 && arm != kRightUpperArm) || (only == 3 && arm != kLeftUpperArm)) continue;
    const Vector3d shoulder = body.frames[arm].translation();
    const std::vector<Vector3d>& points = by_side[arm == kRightUpperArm ? 0 : 1];
    const std::optional<Vector3d> farthest = FarthestArmPoint(points, shoulder);
    std::vector<Vector3d> upper_points;
    for (const Vector3d& p : points) {
      const double d = (p - shoulder).norm();
      if (d > 0.06 && d < shape_.upper_arm_m) upper_points.push_back(p);
    }
    Vector3d upper, fore;
    if (!farthest) {
      // No arm seen apart from the body: most likely hanging at rest, but
      // an arm in front of the torso in every view is not seen either, so
      // half the time the arm keeps its pose.
      if (coin(rng_) < 0.5) continue;
      const Eigen::Matrix3d world_from_upper = body.frames[kUpperBody].linear();
      const double side = arm == kRightUpperArm ? 1.0 : -1.0;
      upper = fore = (world_from_upper * Vector3d(0.15 * side, 0.0, -1.0)).normalized();
    } else {
      const double reach = shape_.upper_arm_m + shape_.forearm_m + 0.5 * shape_.hand_m;
      upper = fore = (*farthest - shoulder).normalized();
      if ((*farthest - shoulder).norm() < 0.9 * reach && !upper_points.empty()) {
        std::uniform_int_distribution<size_t> pick(0, upper_points.size() - 1);
        upper = (upper_points[pick(rng_)] - shoulder).normalized();
        const Vector3d elbow = shoulder + shape_.upper_arm_m * upper;
        if ((*farthest - elbow).norm() > 0.05) fore = (*farthest - elbow).normalized();
      }
    }
    const Vector3d noise_u(jitter(rng_), jitter(rng_), jitter(rng_));
    const Vector3d noise_f(jitter(rng_), jitter(rng_), jitter(rng_));
    SetArmDirections(shape_, &pose, arm, (upper + noise_u).normalized(), (fore + noise_f).normalized());
  }
  return pose;
}

BodyPose PoseTracker::DefaultPoseProposal(const BodyPose& current, const FrameFeatures& features) {
  std::uniform_int_distribution<int> which(0, 3);
  const Vector2d root = features.placement->root.head<2>();
  const double yaw = current.dof[kDofYaw];
  BodyPose p;
  switch (which(rng_)) {
    case 0:
      p = StandingPose(shape_, root, yaw);
      break;
    case 1:
      p = ScarecrowPose(shape_, root, yaw);
      break;
    default: {  // pointing forward with one arm, the other hanging
      p = StandingPose(shape_, root, yaw);
      const int sh = which(rng_) % 2 == 0 ? kDofRightShoulderAzimuth : kDofLeftShoulderAzimuth;
      p.dof[sh] = M_PI / 2;
      p.dof[sh + 1] = M_PI / 2;
    }
  }
  return p;
}

BodyPose PoseTracker::TurnedPose(const BodyPose& current, double yaw) const {
  const PosedBody body = PoseBody(shape_, current);
  BodyPose next = current;
  next.dof[kDofYaw] = yaw;
  next.dof[kDofWaistZ] = 0;
  // Turned about the trunk's axis (the lower body's ellipsoid stays where
  // the silhouettes put it; the spine lies spine_depth_m behind it).
  const Vector2d trunk = body.segments[kLowerBody].center.head<2>();
  const Vector2d moved = PoseBody(shape_, next).segments[kLowerBody].center.head<2>();
  next.dof[kDofX] += trunk.x() - moved.x();
  next.dof[kDofY] += trunk.y() - moved.y();
  const struct {
    int segment, shoulder, elbow, wrist;
  } arms[] = {{kRightUpperArm, kModelRightShoulder, kModelRightElbow, kModelRightWrist},
              {kLeftUpperArm, kModelLeftShoulder, kModelLeftElbow, kModelLeftWrist}};
  for (const auto& a : arms) {
    const Vector3d upper = body.joints[a.elbow] - body.joints[a.shoulder];
    const Vector3d fore = body.joints[a.wrist] - body.joints[a.elbow];
    if (upper.norm() < 1e-6 || fore.norm() < 1e-6) continue;
    SetArmDirections(shape_, &next, a.segment, upper.normalized(), fore.normalized());
  }
  return next;
}

BodyPose FlippedPose(const BodyPose& pose) {
  BodyPose f = pose;
  auto& q = f.dof;
  q[kDofYaw] += M_PI;
  q[kDofWaistX] = -pose.dof[kDofWaistX];
  q[kDofWaistY] = -pose.dof[kDofWaistY];
  q[kDofNeckAzimuth] = pose.dof[kDofNeckAzimuth] + M_PI;
  // A right arm along body direction (x, y, z) becomes a left arm along
  // (-x, -y, z): the same zenith, the azimuth negated (the left arm's angles
  // mirror x).
  q[kDofLeftShoulderAzimuth] = -pose.dof[kDofRightShoulderAzimuth];
  q[kDofLeftShoulderZenith] = pose.dof[kDofRightShoulderZenith];
  q[kDofRightShoulderAzimuth] = -pose.dof[kDofLeftShoulderAzimuth];
  q[kDofRightShoulderZenith] = pose.dof[kDofLeftShoulderZenith];
  q[kDofLeftShoulderTwist] = q[kDofRightShoulderTwist] = 0.0;
  q[kDofLeftElbowAzimuth] = -pose.dof[kDofRightElbowAzimuth];
  q[kDofLeftElbowZenith] = pose.dof[kDofRightElbowZenith];
  q[kDofRightElbowAzimuth] = -pose.dof[kDofLeftElbowAzimuth];
  q[kDofRightElbowZenith] = pose.dof[kDofLeftElbowZenith];
  ClampToJointLimits(&f);
  return f;
}

BodyShape PoseTracker::ShapeFor(double height_m, double girth) const {
  const double thickness =
      arm_diameter_m_ > 0
          ? std::clamp(arm_diameter_m_ / (options_.arm_reference_diameter * height_m), 1.0, options_.max_arm_thickness)
          : 1.0;
  return BodyShape::FromHeight(height_m, girth, thickness);
}

void PoseTracker::CapRise(BodyPose* pose) const {
  pose->dof[kDofZ] = std::min(pose->dof[kDofZ], shape_.waist_height_m + options_.max_rise_m);
}

BodyPose PoseTracker::Propose(const BodyPose& current, const BodyPose& previous, const FrameFeatures& features,
                              double dt) {
  const double total = options_.p_random_walk + options_.p_body_position + options_.p_arm_direction +
                       options_.p_default_pose;
  std::uniform_real_distribution<double> u(0.0, total);
  const double choice = u(rng_);
  std::normal_distribution<double> n01(0.0, 1.0);
  const double k = std::sqrt(std::max(dt, 1e-3) * 30.0);
  BodyPose next = current;
  const double flip_or_turn = u(rng_);
  if (flip_or_turn < options_.p_turn * total && !walking_ && !entering_) {
    // Turned (see PoseTrackerOptions::p_turn); not while walking or entering,
    // where the heading is the walk's.
    const double yaw = u(rng_) < 0.5 * total ? YawFacing(facing_xy_) + 0.15 * n01(rng_)
                                             : current.dof[kDofYaw] + 0.8 * n01(rng_);
    next = TurnedPose(current, yaw);
  } else if (flip_or_turn < (options_.p_turn + options_.p_flip) * total) {
    // Front/back flip (silhouettes barely tell them apart): turned half way
    // round with the arms swapped so the silhouettes stay nearly the same;
    // the heading priors and raised arms' joint limits decide.
    next = FlippedPose(current);
  } else if (lost_ && u(rng_) < 0.5 * total) {
    // Lost (the best particle explained the silhouettes poorly last frame):
    // half the particles restart from default poses where the hull is,
    // facing the screen (thesis 6.6: recovery within 2-3 frames).
    BodyPose facing = current;
    facing.dof[kDofYaw] = YawFacing(facing_xy_) + 0.3 * n01(rng_);
    next = DefaultPoseProposal(facing, features);
  } else if (choice < options_.p_random_walk) {
    // Random walk with velocity (thesis 6.3.2), capped.
    for (int d = 0; d < kDofCount; ++d) {
      double v = current.dof[d] - previous.dof[d];
      if (IsAngleDof(d)) v = WrapAngle(v);
      const double cap = d < kDofYaw ? options_.max_step_m : options_.max_step_rad;
      next.dof[d] += options_.velocity_damping * std::clamp(v, -cap, cap);
    }
    next.dof[kDofX] += k * options_.sigma_position_m * n01(rng_);
    next.dof[kDofY] += k * options_.sigma_position_m * n01(rng_);
    next.dof[kDofZ] += 0.3 * k * options_.sigma_position_m * n01(rng_);
    next.dof[kDofYaw] += k * options_.sigma_yaw_rad * n01(rng_);
    // The body's pitch and roll stay as they are (zero): the legs' ellipsoid
    // says little about them, and bowing or leaning is the waist's.
    for (int d : {kDofWaistZ, kDofWaistX, kDofWaistY, kDofNeckAzimuth, kDofNeckZenith}) {
      next.dof[d] += k * options_.sigma_torso_rad * n01(rng_);
    }
    for (int d : {kDofRightShoulderAzimuth, kDofRightShoulderZenith, kDofLeftShoulderAzimuth, kDofLeftShoulderZenith,
                  kDofRightElbowAzimuth, kDofRightElbowZenith, kDofLeftElbowAzimuth, kDofLeftElbowZenith}) {
      next.dof[d] += k * options_.sigma_arm_rad * n01(rng_);
    }
    next.dof[kDofRightShoulderTwist] = next.dof[kDofLeftShoulderTwist] = 0.0;
  } else if (choice < options_.p_random_walk + options_.p_body_position) {
    // Body position (thesis 6.3.2): the x and y of a random 3D torso axis
    // point (the trunk's middle, the waist spine_depth_m behind it), else
    // the voxel hull's root; while the user walks, the heading from the
    // hull's motion (people face where they walk).
    if (walking_) next.dof[kDofYaw] = YawFacing(velocity_xy_.normalized()) + 0.1 * n01(rng_);
    const Vector2d noise(0.02 * n01(rng_), 0.02 * n01(rng_));
    if (!torso_xy_.empty()) {
      std::uniform_int_distribution<size_t> pick(0, torso_xy_.size() - 1);
      const Vector2d xy =
          torso_xy_[pick(rng_)] + noise - shape_.spine_depth_m * FacingDirection(next.dof[kDofYaw]);
      next.dof[kDofX] = xy.x();
      next.dof[kDofY] = xy.y();
    } else {
      PlaceRoot(shape_, &next, features.placement->root.head<2>() + noise);
    }
  } else if (choice < options_.p_random_walk + options_.p_body_position + options_.p_arm_direction) {
    next = ArmDirectionProposal(current, features);
  } else {
    next = DefaultPoseProposal(current, features);
  }
  // While the user walks, a particle facing more than 90 deg away from the
  // walking direction is turned to it (people do not walk backwards onto a
  // stage; silhouettes cannot tell front from back).
  // An entering user (first seen half in view) likewise faces the stage's
  // centre until the walk itself is seen.
  if (walking_ || entering_) {
    const double heading = YawFacing(walking_ ? velocity_xy_.normalized() : walk_dir_);
    if (std::cos(next.dof[kDofYaw] - heading) < 0) next = FlippedPose(next);
  }
  ClampToJointLimits(&next);
  CapRise(&next);
  return next;
}

PoseEstimate PoseTracker::Step(const FrameFeatures& features, double dt) {
  const auto start = std::chrono::steady_clock::now();
  PoseEstimate out;
  if (!features.placement || features.cameras.size() != cameras_.size()) {
    active_ = false;
    lost_ = false;
    lifted_age_s_ = {kNever, kNever};
    out.ms_total = Millis(start);
    return out;
  }
  std::vector<SilhouetteView> views;
  std::vector<IcpView> icp_views;
  for (size_t c = 0; c < cameras_.size(); ++c) {
    views.emplace_back(cameras_[c], features.cameras[c].silhouette, map1_[c], map2_[c], options_.observation.scale);
    if (options_.refine_fraction > 0 && options_.icp.iterations > 0) {
      icp_views.push_back({cameras_[c], projections_[c], OutlinePolygons(views.back().ideal_silhouette())});
    }
  }

  // The hull's ground velocity over the last half second (single frames are
  // too noisy: a centimetre of jitter per frame reads as 0.4 m/s): a walking
  // user's heading.
  const Vector2d root_xy = features.placement->root.head<2>();
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
    }
    moving_frames_ = steady ? moving_frames_ + 1 : 0;
    walking_ = moving_frames_ >= 2;
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

  // What the proposals read of the 3D axis points, once per frame.
  arm_chains_ = ChainArmPoints(features.axis3d);
  torso_xy_.clear();
  std::vector<double> arm_diameters;  // this frame's, metres
  for (const AxisPoint3d& a : features.axis3d) {
    if (a.part == BodyPart::kTorso) torso_xy_.push_back(a.p_in_world.head<2>());
    if (a.part == BodyPart::kArm && a.diameter_m > 0) arm_diameters.push_back(a.diameter_m);
  }

  std::vector<BodyPose> proposed;
  if (!active_) {
    Initialise(features);
    active_ = true;
    proposed = particles_;
  } else {
    if (heights_.empty() && InView(features.placement->root)) {
      // Until the height is measured (below), a model more than 10 % off the
      // hull's top takes the top's height: a user first seen half in view
      // can give a low top, and a model left that small explains the
      // silhouettes too poorly to be tracked and measured (tracker seed 3 on
      // p2's demo stayed 1.2 m tall for the whole session).
      const double height = std::clamp(features.placement->top_m, 1.2, 2.2);
      if (std::abs(height / shape_.height_m - 1) > 0.1) {
        const double ratio = height / shape_.height_m;
        shape_ = ShapeFor(height, shape_.girth);
        for (BodyPose& p : particles_) p.dof[kDofZ] *= ratio;
        for (BodyPose& p : previous_) p.dof[kDofZ] *= ratio;
      }
    }
    for (size_t i = 0; i < particles_.size(); ++i) {
      proposed.push_back(Propose(particles_[i], previous_[i], features, dt));
    }
  }
  if (hook_) {
    // Posture-recognition proposals replace the last particles.
    std::vector<BodyPose> extra = hook_(features, shape_);
    for (size_t i = 0; i < extra.size() && i < proposed.size(); ++i) {
      proposed[proposed.size() - 1 - i] = extra[i];
    }
  }

  const int n = static_cast<int>(proposed.size());
  std::vector<double> log_likelihood(n);
  const auto t_obs = std::chrono::steady_clock::now();
  cv::parallel_for_(cv::Range(0, n), [&](const cv::Range& r) {
    for (int i = r.start; i < r.end; ++i) {
      log_likelihood[i] = Evaluate(proposed[i], views, nullptr) + HeadingPrior(proposed[i]);
    }
  });
  out.ms_observation = Millis(t_obs);

  // Refine-prediction (thesis 6.3.3): 2D-3D ICP on a random subset; a refined
  // particle replaces its original when it explains the silhouettes better.
  const auto t_refine = std::chrono::steady_clock::now();
  const int refine = static_cast<int>(std::round(options_.refine_fraction * n));
  if (refine > 0 && options_.icp.iterations > 0) {
    std::vector<int> order(n);
    std::iota(order.begin(), order.end(), 0);
    std::shuffle(order.begin(), order.end(), rng_);
    order.resize(refine);
    std::vector<BodyPose> refined(refine);
    std::vector<double> refined_ll(refine);
    cv::parallel_for_(cv::Range(0, refine), [&](const cv::Range& r) {
      for (int j = r.start; j < r.end; ++j) {
        refined[j] = RefineIcp(shape_, proposed[order[j]], icp_views, options_.icp);
        CapRise(&refined[j]);
        refined_ll[j] = Evaluate(refined[j], views, nullptr) + HeadingPrior(refined[j]);
      }
    });
    for (int j = 0; j < refine; ++j) {
      if (refined_ll[j] > log_likelihood[order[j]]) {
        proposed[order[j]] = refined[j];
        log_likelihood[order[j]] = refined_ll[j];
      }
    }
  }
  out.ms_refine = Millis(t_refine);

  const int best = static_cast<int>(std::max_element(log_likelihood.begin(), log_likelihood.end()) -
                                    log_likelihood.begin());
  out.log_likelihood = Evaluate(proposed[best], views, &out.overlap);
  const double mean_overlap = std::accumulate(out.overlap.begin(), out.overlap.end(), 0.0) / out.overlap.size();
  const bool fits = mean_overlap >= options_.min_overlap;
  out.in_view = InView(features.placement->root);
  out.tracking = fits && out.in_view;
  out.pose = proposed[best];

  // Height (thesis 6.1.2): configured when the user enters, from the hull's
  // top while the arms are below the shoulders; the median over the first
  // frames. The top alone: checking it against the silhouettes at scales of
  // 0.94-1.06 about it made p2, p3 and p4 3-5 cm too tall, and the filter
  // crouched the model to fit (five demos, seeds 4-7: waist 4.16 -> 3.65
  // cm, arm joints 3.58 -> 3.35). The girth is searched against the
  // silhouettes. The particles keep their angles and move their waist
  // heights with the scale.
  {
    const PosedBody body = PoseBody(shape_, out.pose);
    const bool arms_low = body.joints[kModelRightHandTip].z() < body.joints[kModelRightShoulder].z() &&
                          body.joints[kModelLeftHandTip].z() < body.joints[kModelLeftShoulder].z();
    if (out.tracking && arms_low && static_cast<int>(heights_.size()) < options_.height_frames) {
      // Searched with the torso and head upright: a twisted torso is how a
      // too-narrow model covers a wide body. The girth reaches 2.4: capped
      // at 1.5, the heavy p3 (who takes 1.65-2.0) kept a torso too narrow,
      // and the filter spread the arms to cover it (full suite, seeds 1-3:
      // p3's rest 93 -> 98 %, waist 5.6 -> 4.0 cm).
      const double top_height = std::clamp(features.placement->top_m, 1.2, 2.2);
      double best_ll = -std::numeric_limits<double>::infinity(), best_girth = 1.0;
      BodyPose upright = out.pose;
      for (int d : {kDofWaistZ, kDofWaistX, kDofWaistY, kDofNeckAzimuth, kDofNeckZenith}) upright.dof[d] = 0;
      upright.dof[kDofZ] *= top_height / shape_.height_m;
      for (double girth : {0.9, 1.05, 1.2, 1.35, 1.5, 1.65, 1.8, 2.0, 2.2, 2.4}) {
        const double ll = Evaluate(ShapeFor(top_height, girth), upright, views, nullptr);
        if (ll > best_ll) {
          best_ll = ll;
          best_girth = girth;
        }
      }
      heights_.push_back(top_height);
      girths_.push_back(best_girth);
      const double height = std::clamp(Median(heights_), 1.2, 2.2);
      const double ratio = height / shape_.height_m;
      shape_ = ShapeFor(height, Median(girths_));
      for (BodyPose& p : proposed) p.dof[kDofZ] *= ratio;
      for (BodyPose& p : particles_) p.dof[kDofZ] *= ratio;
      out.pose.dof[kDofZ] *= ratio;
    }
  }
  // Arm thickness: p5's jacket sleeves measure a third thicker than bare
  // arms, and the model's thinner arms could lie anywhere inside them (five
  // demos, seeds 1-7: p5's elbows 5.0-5.3 cm; with thicker arms 3.9-4.2).
  // The 3D arm axis points measure the arms across; the girth, measured on
  // the torso, does not tell a jacket from a broad chest. Kept in metres, so
  // that a height measured later scales the thickness.
  if (out.tracking && arm_frames_ < options_.arm_thickness_frames && !arm_diameters.empty()) {
    arm_diameters_.insert(arm_diameters_.end(), arm_diameters.begin(), arm_diameters.end());
    ++arm_frames_;
    if (static_cast<int>(arm_diameters_.size()) >= options_.arm_thickness_min_points) {
      arm_diameter_m_ = Median(arm_diameters_);
      shape_ = ShapeFor(shape_.height_m, shape_.girth);
    }
  }
  out.shape = shape_;
  out.body = PoseBody(shape_, out.pose);
  if (!out.tracking) lifted_age_s_ = {kNever, kNever};
  if (out.tracking && rest_ && !rest_->empty()) {
    // Thesis 6.4: an arm at rest is forced down. The SVM's part of the
    // decision is a vote of the particles, weighted by their likelihood
    // tempered tenfold: an arm against the torso is poorly determined, and
    // the best particle alone flickers between nearby poses. Besides it, an
    // arm the 3D axis points show apart from the body is judged by their
    // angle, and one they do not show by the likelihood-ratio test
    // (PoseTrackerOptions).
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
                                            out.body.joints[kModelRightShoulder], out.body.joints[kModelLeftShoulder]);
    for (int side = 0; side < 2; ++side) {
      const bool left = side == 1;
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
      bool at_rest = rest_weight > 0.5 * total_weight;
      // An arm the 3D axis points show apart from the body is where they
      // are: at rest when they hang within rest_seen_max_angle_deg of
      // straight down. Only an arm they do not show (against the torso, or
      // in front of it in every view) is left to the likelihood-ratio test,
      // which would take an arm just lifting off the side for one still
      // hanging; and not one just seen lifted, which has left the
      // silhouettes rather than dropped to the side unseen.
      const Vector3d shoulder = out.body.joints[left ? kModelLeftShoulder : kModelRightShoulder];
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
        out.rest[side] = false;
        continue;
      }
      // Forced down: the hanging pose the silhouettes like best, out to the
      // side or a little forward, the forearm straight or bent forward.
      // People seldom hang their arms dead straight; against a single
      // straight pose a bent hanging arm lost enough overlap to fail the
      // likelihood-ratio test.
      const int sh = left ? kDofLeftShoulderAzimuth : kDofRightShoulderAzimuth;
      const int el = left ? kDofLeftElbowAzimuth : kDofRightElbowAzimuth;
      BodyPose down = out.pose;
      double down_ll = -std::numeric_limits<double>::infinity();
      for (const auto& [shoulder_azimuth, shoulder_zenith] : {std::pair{0.0, 0.1}, std::pair{M_PI / 2, 0.15}}) {
        for (const double elbow_zenith : {0.0, 0.4, 0.8}) {
          BodyPose candidate = out.pose;
          candidate.dof[sh] = shoulder_azimuth;
          candidate.dof[sh + 1] = shoulder_zenith;
          candidate.dof[sh + 2] = 0.0;
          candidate.dof[el] = M_PI / 2;  // forward
          candidate.dof[el + 1] = elbow_zenith;
          const double ll = Evaluate(candidate, views, nullptr);
          if (ll > down_ll) {
            down_ll = ll;
            down = candidate;
          }
        }
      }
      if (!at_rest) {
        // The likelihood-ratio test against the estimate as it stands (the
        // other arm perhaps forced down).
        if (!estimate_ll) estimate_ll = Evaluate(out.pose, views, nullptr);
        at_rest = (*estimate_ll - down_ll) / options_.observation.sharpness < options_.rest_max_log_overlap_loss;
      }
      out.rest[side] = at_rest;
      if (at_rest) {
        out.pose = down;
        estimate_ll = down_ll;
      }
    }
    out.body = PoseBody(shape_, out.pose);
  }
  if (out.tracking && options_.head_from_hull && features.voxels && HeadSeenByAll(out.body, views)) {
    // The head centre where the hull shows it (pointing.h): the pointing
    // rays' origin and the head joint.
    const auto head = HullHeadCentre(*features.voxels, out.body.joints[kModelHead],
                                     out.body.frames[kUpperBody].linear() * Vector3d::UnitY(), shape_.height_m,
                                     options_.hull_head);
    if (head) out.body.joints[kModelHead] = *head;
  }
  if (out.tracking) {
    if (!out.rest[0].value_or(false)) {
      out.pointing[0] = Pointing(out.body.joints[kModelHead], out.body.joints[kModelRightHandTip], screens_);
    }
    if (!out.rest[1].value_or(false)) {
      out.pointing[1] = Pointing(out.body.joints[kModelHead], out.body.joints[kModelLeftHandTip], screens_);
    }
  }

  // Resampling (systematic), carrying each particle's previous state along
  // for the velocity.
  const double max_ll = log_likelihood[best];
  std::vector<double> cumulative(n);
  double sum = 0;
  for (int i = 0; i < n; ++i) {
    sum += std::exp(log_likelihood[i] - max_ll);
    cumulative[i] = sum;
  }
  std::uniform_real_distribution<double> u0(0.0, sum / n);
  double pointer = u0(rng_);
  std::vector<BodyPose> next(n), next_previous(n);
  const std::vector<BodyPose>& before = particles_;
  int i = 0;
  for (int j = 0; j < n; ++j) {
    while (i < n - 1 && cumulative[i] < pointer) ++i;
    next[j] = proposed[i];
    next_previous[j] = i < static_cast<int>(before.size()) ? before[i] : proposed[i];
    pointer += sum / n;
  }
  particles_ = std::move(next);
  previous_ = std::move(next_previous);
  lost_ = !fits;
  out.ms_total = Millis(start);
  return out;
}

}  // namespace irbench
