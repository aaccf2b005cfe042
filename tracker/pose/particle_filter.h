#pragma once
// The particle filter over the 21-DOF body (thesis 6.3, "Particle
// Filtering"), one frame's steps in the order PoseTracker::Step takes them:
//   1. propose each particle's next pose (6.3.2, "Proposal Functions"):
//      ProposeParticle, which picks among a turn (TurnedPose), a front/back
//      flip (FlippedPose), a restart from a default pose while lost, the
//      random walk with velocity, the body position from the torso axis
//      points or the voxel hull, the arm directions from the 3D arm axis
//      points and the default poses;
//   2. weigh them by the observation probability (6.3.1): WeighParticles;
//   3. refine a random subset by 2D-3D ICP (6.3.3, "Particle Refinement";
//      icp.h): RefineParticles;
//   4. resample (systematic): ResampleSystematic.
// Poses are in the world frame (body_model.h), metres and radians. Every
// random draw comes from the tracker's one generator, passed by reference.

#include <Eigen/Core>
#include <array>
#include <functional>
#include <optional>
#include <random>
#include <vector>

#include "tracker/body_model/body_model.h"
#include "tracker/frontend/frontend.h"
#include "tracker/pose/arm_points.h"
#include "tracker/pose/icp.h"
#include "tracker/pose/pose_tracker_options.h"

namespace irbench {

// One arm's posture as the posture recogniser (thesis 5.1) names it: at rest,
// or the hand tip seen from the shoulder at an elevation in
// [min_deg, max_deg] above the upper body's horizontal plane.
struct ArmPostureBand {
  bool rest = false;
  double min_deg = 0, max_deg = 0;
};
// A recognised two-arm posture: its two atoms' bands, which arm holds which
// unknown (the recogniser sees the shape, not the sides).
using PostureBands = std::array<ArmPostureBand, 2>;

// What the proposals (thesis 6.3.2) read of this frame and of the tracker's
// state; the references must outlive the proposals.
struct ProposalContext {
  const PoseTrackerOptions& options;
  const BodyShape& shape;
  const FrameFeatures& features;  // features.placement must be set
  const ArmChains& arm_chains;    // this frame's 3D arm axis points
  const std::vector<Eigen::Vector2d>&
      torso_xy;                 // this frame's torso axis points (world x, y, metres)
  Eigen::Vector2d facing_xy;    // the heading users mostly face (towards the screens), unit
  Eigen::Vector2d velocity_xy;  // the hull's ground velocity, m/s
  Eigen::Vector2d
      walk_dir;           // the last walking direction (or the stage's centre while entering), unit
  bool walking = false;   // the user walks: the heading is the walk's
  bool entering = false;  // first seen half in view, not yet seen walking
  bool lost = false;      // last frame's best particle explained the silhouettes poorly
  // The posture recognised in the frame-set before (PoseTracker::set_posture);
  // none: the posture proposal falls back to the random walk.
  std::optional<PostureBands> posture;
  // How far the hull's lowest part lies above the floor (FloorGap): a jump.
  // The waist may rise that much more than max_rise_m, and the body
  // position proposal lifts the waist by it.
  double floor_gap_m = 0;
  // How much higher than max_rise_m the waist may rise: the larger of
  // floor_gap_m and the tiptoe rise (PoseTracker::ExtraRise).
  double extra_rise_m = 0;
};

// A particle's log-likelihood: the observation (thesis 6.3.1) plus the
// heading prior.
using PoseScore = std::function<double(const BodyPose&)>;

// Thesis 6.3.2: the next pose of the particle at `current` that was at
// `previous` a frame before, `dt` seconds later: one proposal function
// picked at random (PoseTrackerOptions' p_*), then turned to the walk's
// heading while the user walks or enters, joint limits applied and the rise
// capped (CapRise).
BodyPose ProposeParticle(const BodyPose& current,
                         const BodyPose& previous,
                         double dt,
                         const ProposalContext& context,
                         std::mt19937_64& rng);

// Thesis 6.3.2, random walk with velocity: `current` moved on by the damped,
// capped change since `previous`, plus Gaussian noise scaled by `k`
// (sqrt(dt * 30)); draws from `n01` (standard normal) with `rng`.
BodyPose RandomWalkProposal(const BodyPose& current,
                            const BodyPose& previous,
                            double k,
                            const PoseTrackerOptions& options,
                            std::normal_distribution<double>& n01,
                            std::mt19937_64& rng);

// Thesis 6.3.2, body position: `current` moved to a random 3D torso axis
// point (the trunk's middle, the waist spine_depth_m behind it), else to the
// voxel hull's root; while the user walks, turned to the walking direction.
BodyPose BodyPositionProposal(const BodyPose& current,
                              const ProposalContext& context,
                              std::normal_distribution<double>& n01,
                              std::mt19937_64& rng);

// Thesis 6.3.2, arm directions from the 3D arm axis points: both arms or one
// (at random) pointed along the points the arm's shoulder owns; an arm they
// do not show hangs down half the time.
BodyPose ArmDirectionProposal(BodyPose pose, const ProposalContext& context, std::mt19937_64& rng);

// Thesis 6.3.2, "Shape Descriptor & Posture Recognition Function": the arms
// of `current` moved into the recognised posture. The pair's two bands are
// given to the arms the cheaper way (each arm's hand elevation nearest its
// band; ties at random); an arm outside its band gets an elevation drawn
// uniformly in it, keeping its horizontal direction (sideways to forward at
// random where it points straight up or down), straight, or hangs when the
// band is rest. None when both arms already lie in their bands.
std::optional<BodyPose> PostureProposal(const BodyPose& current,
                                        const BodyShape& shape,
                                        const PostureBands& posture,
                                        std::mt19937_64& rng);

// Thesis 6.3.2, default poses at the hull's root with `current`'s heading:
// standing, scarecrow, or pointing forward with one arm.
BodyPose DefaultPoseProposal(const BodyPose& current,
                             const ProposalContext& context,
                             std::mt19937_64& rng);

// `current` turned to heading `yaw` (radians) about the trunk's axis, its
// arms kept pointing where they point in the world (PoseTrackerOptions::p_turn).
BodyPose TurnedPose(const BodyShape& shape, const BodyPose& current, double yaw);

// The front/back twin of `pose`: turned by pi about z through the waist
// joint, the arms swapped and mirrored, so that its silhouettes are nearly
// those of `pose`: the arms land exactly where they were, the trunk and head
// (spine_depth_m ahead of the spine) move by twice that, a few centimetres
// the filter's next steps take up.
BodyPose FlippedPose(const BodyPose& pose);

// The waist at most `max_rise_m` metres above its standing height
// (shape.waist_height_m).
void CapRise(const BodyShape& shape, double max_rise_m, BodyPose* pose);

// Thesis 6.3.1: every particle's score, evaluated in parallel.
std::vector<double> WeighParticles(const std::vector<BodyPose>& particles, const PoseScore& score);

// Thesis 6.3.3, refine-prediction: 2D-3D ICP (icp.h) on a random subset of
// round(options.refine_fraction * n) particles; a refined particle (its rise
// capped at max_rise_m + extra_rise_m) replaces its original, and its score
// the original's, when it scores higher. Nothing without ICP iterations.
void RefineParticles(const BodyShape& shape,
                     const std::vector<IcpView>& icp_views,
                     const PoseTrackerOptions& options,
                     const PoseScore& score,
                     std::mt19937_64& rng,
                     std::vector<BodyPose>* particles,
                     std::vector<double>* log_likelihood,
                     double extra_rise_m = 0);

// The index of the highest log-likelihood (the first of equals).
int BestParticle(const std::vector<double>& log_likelihood);

// Thesis 6.3: systematic resampling of `proposed` by weights
// exp(log_likelihood - max_ll). `particles` holds the particles the
// proposals started from and receives the resampled ones; `previous`
// receives each one's state before it (for the random walk's velocity).
void ResampleSystematic(const std::vector<BodyPose>& proposed,
                        const std::vector<double>& log_likelihood,
                        double max_ll,
                        std::mt19937_64& rng,
                        std::vector<BodyPose>* particles,
                        std::vector<BodyPose>* previous);

}  // namespace irbench
