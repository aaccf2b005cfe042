#pragma once
// Pose tracking (thesis 6.3, 6.5): a particle filter over the 21-DOF ellipsoid
// body whose observation is the silhouette overlap of every camera
// (observation.h), with the thesis's proposal functions — a random walk with
// velocity, the body position from the voxel hull, arm directions from the 3D
// arm axis points, default poses, and the recognised posture (set_posture) — a
// 2D-3D ICP refinement of a random subset (icp.h), joint limits and
// resampling (particle_filter.h). The model is sized to the user as they
// enter (body_calibration.h, thesis 6.1.2). The best particle gives the
// joints and the pointing rays.
//
// It reads only front-end features (silhouettes, 3D axis points, the voxel
// hull's placement), the calibration and the surveyed screens: never truth.

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <deque>
#include <memory>
#include <optional>
#include <random>
#include <span>
#include <vector>

#include "geometry/camera.h"
#include "geometry/screen.h"
#include "tracker/frontend/frontend.h"
#include "tracker/body_model/body_model.h"
#include "tracker/pose/arm_points.h"
#include "tracker/pose/body_calibration.h"
#include "tracker/pose/icp.h"
#include "tracker/pose/observation.h"
#include "tracker/pose/particle_filter.h"  // FlippedPose
#include "tracker/pose/pointing.h"
#include "tracker/pose/pose_tracker_options.h"  // PoseTrackerOptions
#include "tracker/pose/rest_state.h"

namespace irbench {

struct PoseEstimate {
  // A person fully in view whose pose the filter explains; false on an empty
  // stage, while the user is still partly outside some camera's view
  // (in_view false), and when the best particle explains the silhouettes
  // poorly (lost).
  bool tracking = false;
  bool in_view = false;
  BodyShape shape;
  BodyPose pose;
  PosedBody body;
  // Per camera, the best particle's overlap ratio; NaN for a camera left out
  // of the frame-set (FrameFeatures::left_out).
  std::vector<double> overlap;
  double log_likelihood = 0;
  std::optional<PointingRay> pointing[2];  // right, left; none for an arm at rest
  std::optional<bool> rest[2];              // right, left; none without a rest classifier
  double ms_observation = 0, ms_refine = 0, ms_total = 0;
};

// Does `camera` hold a box of half-width `margin_m` about `root` (x, y),
// from the floor to `height_m`, inside its image (its corners in front of it
// and on its pixels)? The pose tracker's "in view" test.
bool HoldsBox(const Camera& camera, const Eigen::Vector3d& root, double height_m, double margin_m);

class PoseTracker {
 public:
  // `screens` (as surveyed, calib/screens.json) give the pointing targets
  // and the heading users mostly face (towards the screens' centre); may be
  // empty (then +y).
  PoseTracker(std::vector<Camera> cameras, std::vector<ScreenSurface> screens, const PoseTrackerOptions& options);

  // One frame-set: `dt` seconds after the previous one.
  PoseEstimate Step(const FrameFeatures& features, double dt);

  // The posture the posture recogniser (thesis 5.1) found in this frame-set,
  // for the next Step's posture proposal (PoseTrackerOptions::p_posture);
  // none: no posture recognised.
  void set_posture(std::optional<PostureBands> posture) { posture_ = posture; }
  // The rest-state classifier (thesis 6.4); an arm it finds at rest is
  // forced down in the estimate.
  void set_rest_classifier(std::shared_ptr<const RestClassifier> rest) { rest_ = std::move(rest); }
  // Scatters the particles uniformly over the stage (for the recovery test:
  // thesis 6.6 reports recovery in 2-3 frames).
  void Scatter();
  const std::vector<BodyPose>& particles() const { return particles_; }

 private:
  // Step's parts, in the order it takes them (pose_tracker.cc).
  // The frame's silhouettes as overlap views and, when ICP refines, outlines.
  void MakeViews(const FrameFeatures& features, std::vector<SilhouetteView>* views,
                 std::vector<IcpView>* icp_views) const;
  // The hull's ground velocity, walking_, the walk's memory and entering_
  // from the hull's root `root_xy` (world, metres) `dt` seconds on.
  void UpdateWalking(const Eigen::Vector2d& root_xy, double dt);
  // Reads the 3D axis points for the proposals (arm_chains_, torso_xy_);
  // returns this frame's arm diameters (metres).
  std::vector<double> ReadAxisPoints(const FrameFeatures& features);
  // A new user: the model sized to the hull (body_calibration.h) and the
  // particles seeded at its root.
  void Initialise(const FrameFeatures& features);
  // Thesis 6.3.2: this frame's proposed particles (the first frame's seeds
  // on acquiring a user).
  std::vector<BodyPose> ProposeParticles(const FrameFeatures& features, double dt);
  // The best particle as the estimate: pose, overlaps, in view, tracking.
  // Returns whether it explains the silhouettes (min_overlap).
  bool EstimateFromBest(const std::vector<BodyPose>& proposed, int best, const FrameFeatures& features,
                        const std::vector<SilhouetteView>& views, PoseEstimate* out) const;
  // Thesis 6.1.2: the height, girth and arm thickness measured on the
  // estimate; the particles and the estimate rescaled with the model.
  void Calibrate(const FrameFeatures& features, const std::vector<SilhouetteView>& views,
                 const std::vector<double>& arm_diameters, std::vector<BodyPose>* proposed, PoseEstimate* out);
  // Thesis 6.4: each arm's rest state; an arm at rest is forced down.
  void DecideRest(const std::vector<BodyPose>& proposed, const std::vector<double>& log_likelihood, int best,
                  const std::vector<SilhouetteView>& views, double dt, PoseEstimate* out);
  // The rest classifier's vote on one arm, by the voters' weights.
  bool RestVote(const std::vector<std::optional<PosedBody>>& voters, const std::vector<double>& vote_weight,
                bool left) const;
  // One arm of `pose` hanging (the upper arm at each of the hanging
  // directions) with each of the forearms `forearms` ((azimuth, zenith) in
  // the upper arm's frame): where the silhouettes like one better than the
  // log-likelihood `ll`, it becomes `down` and its log-likelihood `ll`;
  // true when one did.
  bool BestHangingArm(const BodyPose& pose, bool left, const std::vector<SilhouetteView>& views,
                      std::span<const std::pair<double, double>> forearms, BodyPose* down, double* ll) const;
  // The head from the hull (pointing.h) and the pointing rays of the arms
  // not at rest.
  void HeadAndPointing(const FrameFeatures& features, const std::vector<SilhouetteView>& views,
                       PoseEstimate* out) const;

  double Evaluate(const BodyPose& pose, const std::vector<SilhouetteView>& views, std::vector<double>* overlaps) const;
  double HeadingPrior(const BodyPose& pose) const;
  // The box HoldsBox checks, about the root, inside the image of every camera
  // that holds it at the stage's centre (holds_stage_).
  bool InView(const Eigen::Vector3d& root) const;
  // Per camera: does it hold a kStageCheckHeightM box at the stage's centre?
  std::vector<bool> holds_stage_;
  static constexpr double kStageCheckHeightM = 2.0;
  // Does the model's head centre fall inside every camera's silhouette? A
  // view that lost the head (dark hair against a dark wall) carved it from
  // the voxel hull too.
  bool HeadSeenByAll(const PosedBody& body, const std::vector<SilhouetteView>& views) const;
  double Evaluate(const BodyShape& shape, const BodyPose& pose, const std::vector<SilhouetteView>& views,
                  std::vector<double>* overlaps) const;

  std::vector<Camera> cameras_;
  std::vector<Eigen::Matrix<double, 3, 4>> projections_;
  std::vector<cv::Mat> map1_, map2_;
  std::vector<ScreenSurface> screens_;
  PoseTrackerOptions options_;
  std::mt19937_64 rng_;
  std::optional<PostureBands> posture_;
  // This frame's FloorGap of the hull (a jump), 0 on the floor.
  double floor_gap_m_ = 0;
  // This frame's rise of the hull's column over the head above the user's
  // height (PoseTrackerOptions::max_tiptoe_m), 0 when none.
  double tiptoe_m_ = 0;
  // How much higher than max_rise_m the waist may rise this frame: the
  // larger of the two above.
  double ExtraRise() const { return std::max(floor_gap_m_, tiptoe_m_); }
  // The head centre of the last tracked estimate, while tracking goes on.
  std::optional<Eigen::Vector3d> last_head_;
  std::shared_ptr<const RestClassifier> rest_;
  Eigen::Vector2d facing_xy_ = Eigen::Vector2d::UnitY();
  // The feet's direction (HullLegs::toes), averaged over feet_memory_s; zero
  // before the feet are seen.
  Eigen::Vector2d feet_toes_ = Eigen::Vector2d::Zero();
  // The root between the legs' measures (root_offset_smoothing_s,
  // root_offset_memory_s); empty while not tracking.
  RootOffsetMemory root_offset_;
  // The feet's average shows a heading: heading_from_feet, and it reaches
  // feet_min_m.
  bool FeetShowHeading() const;
  // The direction a standing user is taken to face: the feet's when they
  // show it (FeetShowHeading), else the screens'.
  Eigen::Vector2d Preferred() const;
  // A move at `velocity_xy` that is a step, not a walk: slower than
  // step_max_speed_mps and more than step_feet_angle_deg away from where the
  // averaged feet point (when they show it).
  bool IsStep(const Eigen::Vector2d& velocity_xy) const;
  // The root from the hull's legs (root_from_hull) and the feet's direction.
  void MeasureLegs(const FrameFeatures& features, double dt, PoseEstimate* out);

  bool active_ = false;
  BodyShape shape_;
  BodyCalibration calibration_;  // the user's height, girth and arm thickness
  std::vector<BodyPose> particles_, previous_;
  std::deque<Eigen::Vector2d> recent_roots_;
  // This frame's 3D arm axis points in chains, and torso axis points (x, y).
  ArmChains arm_chains_;
  std::vector<Eigen::Vector2d> torso_xy_;
  Eigen::Vector2d velocity_xy_ = Eigen::Vector2d::Zero();
  bool walking_ = false;
  int moving_frames_ = 0;
  // The yaw of the last tracked estimate, while tracking goes on.
  std::optional<double> last_yaw_;
  // Seconds tracked without a break (0 before the first tracked frame).
  double tracked_s_ = 0;
  // The last walking direction and how much of it the heading prior still
  // holds (1 while walking, down to 0 over walk_memory_s).
  Eigen::Vector2d walk_dir_ = Eigen::Vector2d::UnitX();
  double walk_memory_ = 0;
  // First seen half in view and not yet seen walking: particles face the
  // stage's centre (walk_dir_), as they face a walk's direction.
  bool entering_ = false;
  bool lost_ = false;
  // The cameras left out of the current frame-set (FrameFeatures::left_out):
  // not in the likelihood, the ICP or the head test.
  std::vector<bool> left_out_;
  bool LeftOut(size_t c) const { return c < left_out_.size() && left_out_[c]; }
  // Per arm (right, left): seconds since the 3D axis points last showed it
  // lifted (PoseTrackerOptions::rest_lifted_angle_deg); kNever when they
  // have shown it below that angle since, or have not shown it.
  static constexpr double kNever = 1e9;
  std::array<double, 2> lifted_age_s_ = {kNever, kNever};
};

}  // namespace irbench
