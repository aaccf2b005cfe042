// The particle filter (thesis 6.3): proposals (6.3.2), weights (6.3.1),
// ICP refinement (6.3.3) and systematic resampling; see particle_filter.h.

#include "tracker/pose/particle_filter.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <opencv2/core/utility.hpp>
#include <optional>
#include <utility>

#include "common/cancel.h"

namespace irbench {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;

bool IsAngleDof(int d) {
  return d >= kDofYaw;
}

// Places the body so that its root lands on `root_xy`.
void PlaceRoot(const BodyShape& shape, BodyPose* pose, const Vector2d& root_xy) {
  const PosedBody body = PoseBody(shape, *pose);
  const Vector2d offset = root_xy - body.joints[kModelRoot].head<2>();
  pose->dof[kDofX] += offset.x();
  pose->dof[kDofY] += offset.y();
}

}  // namespace

BodyPose ArmDirectionProposal(BodyPose pose, const ProposalContext& context, std::mt19937_64& rng) {
  const BodyShape& shape = context.shape;
  const PosedBody body = PoseBody(shape, pose);
  std::normal_distribution<double> jitter(0.0, 0.05);
  const auto by_side = ArmPointsBySide(
      context.arm_chains.points, context.arm_chains.chain, context.arm_chains.count,
      body.frames[kRightUpperArm].translation(), body.frames[kLeftUpperArm].translation());
  // Half the proposals set both arms, the rest one arm (either side alike):
  // the other arm keeps its pose, so that a raised arm the axis points miss
  // this frame is not forced down while the seen one is placed.
  std::uniform_int_distribution<int> which(0, 3);
  const int only = which(rng);  // 0, 1: both arms; 2: right only; 3: left only
  std::uniform_real_distribution<double> coin(0.0, 1.0);
  for (int arm : {kRightUpperArm, kLeftUpperArm}) {
    if ((only == 2 && arm != kRightUpperArm) || (only == 3 && arm != kLeftUpperArm)) continue;
    const Vector3d shoulder = body.frames[arm].translation();
    const std::vector<Vector3d>& points = by_side[arm == kRightUpperArm ? 0 : 1];
    const std::optional<Vector3d> farthest = FarthestArmPoint(points, shoulder);
    std::vector<Vector3d> upper_points;
    for (const Vector3d& p : points) {
      const double d = (p - shoulder).norm();
      if (d > 0.06 && d < shape.upper_arm_m) upper_points.push_back(p);
    }
    Vector3d upper, fore;
    if (!farthest) {
      // No arm seen apart from the body: most likely hanging at rest, but
      // an arm in front of the torso in every view is not seen either, so
      // half the time the arm keeps its pose.
      if (coin(rng) < 0.5) continue;
      const Eigen::Matrix3d world_from_upper = body.frames[kUpperBody].linear();
      const double side = arm == kRightUpperArm ? 1.0 : -1.0;
      upper = fore = (world_from_upper * Vector3d(0.15 * side, 0.0, -1.0)).normalized();
    } else {
      const double reach = shape.upper_arm_m + shape.forearm_m + 0.5 * shape.hand_m;
      upper = fore = (*farthest - shoulder).normalized();
      if ((*farthest - shoulder).norm() < 0.9 * reach && !upper_points.empty()) {
        std::uniform_int_distribution<size_t> pick(0, upper_points.size() - 1);
        upper = (upper_points[pick(rng)] - shoulder).normalized();
        const Vector3d elbow = shoulder + shape.upper_arm_m * upper;
        if ((*farthest - elbow).norm() > 0.05) fore = (*farthest - elbow).normalized();
      }
    }
    const Vector3d noise_u(jitter(rng), jitter(rng), jitter(rng));
    const Vector3d noise_f(jitter(rng), jitter(rng), jitter(rng));
    SetArmDirections(shape, &pose, arm, (upper + noise_u).normalized(),
                     (fore + noise_f).normalized());
  }
  return pose;
}

std::optional<BodyPose> PostureProposal(const BodyPose& current,
                                        const BodyShape& shape,
                                        const PostureBands& posture,
                                        std::mt19937_64& rng) {
  const PosedBody body = PoseBody(shape, current);
  const Eigen::Matrix3d world_from_upper = body.frames[kUpperBody].linear();
  const struct {
    int segment, shoulder, tip;
    double side;  // the arm's side along the upper body's x
  } arms[] = {{kRightUpperArm, kModelRightShoulder, kModelRightHandTip, 1.0},
              {kLeftUpperArm, kModelLeftShoulder, kModelLeftHandTip, -1.0}};
  // Each arm's hand direction in the upper body's frame (x right, y forward, z up).
  std::array<Vector3d, 2> hand;
  for (int a = 0; a < 2; ++a) {
    hand[a] = (world_from_upper.transpose() * (body.joints[arms[a].tip] - body.joints[arms[a].shoulder]))
                  .normalized();
  }
  auto band_of = [](const ArmPostureBand& b) {
    // A hanging arm's hand lies below -60 deg.
    return b.rest ? std::pair{-90.0, -60.0} : std::pair{b.min_deg, b.max_deg};
  };
  auto miss = [&](const Vector3d& d, const ArmPostureBand& b) {
    const double e = std::asin(std::clamp(d.z(), -1.0, 1.0)) * 180 / M_PI;
    const auto [lo, hi] = band_of(b);
    return std::max(0.0, std::max(lo - e, e - hi));
  };
  const double kept = miss(hand[0], posture[0]) + miss(hand[1], posture[1]);
  const double swapped = miss(hand[0], posture[1]) + miss(hand[1], posture[0]);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const bool swap = swapped < kept || (swapped == kept && unit(rng) < 0.5);
  BodyPose next = current;
  bool changed = false;
  std::normal_distribution<double> jitter(0.0, 0.05);
  for (int a = 0; a < 2; ++a) {
    const ArmPostureBand& b = posture[swap ? 1 - a : a];
    if (miss(hand[a], b) == 0) continue;
    changed = true;
    Vector3d dir;
    if (b.rest) {
      dir = Vector3d(0.15 * arms[a].side, 0.0, -1.0).normalized();
    } else {
      const auto [lo, hi] = band_of(b);
      const double e = (lo + (hi - lo) * unit(rng)) * M_PI / 180;
      Vector2d h = hand[a].head<2>();
      if (h.norm() < 0.2) {
        const double t = 0.5 * M_PI * unit(rng);  // sideways (0) to forward
        h = Vector2d(arms[a].side * std::cos(t), std::sin(t));
      }
      h.normalize();
      dir = Vector3d(std::cos(e) * h.x(), std::cos(e) * h.y(), std::sin(e));
    }
    const Vector3d world = world_from_upper * dir;
    const Vector3d noise_u(jitter(rng), jitter(rng), jitter(rng));
    const Vector3d noise_f(jitter(rng), jitter(rng), jitter(rng));
    SetArmDirections(shape, &next, arms[a].segment, (world + noise_u).normalized(), (world + noise_f).normalized());
  }
  if (!changed) return std::nullopt;
  return next;
}

BodyPose DefaultPoseProposal(const BodyPose& current,
                             const ProposalContext& context,
                             std::mt19937_64& rng) {
  const BodyShape& shape = context.shape;
  std::uniform_int_distribution<int> which(0, 3);
  const Vector2d root = context.features.placement->root.head<2>();
  const double yaw = current.dof[kDofYaw];
  BodyPose p;
  switch (which(rng)) {
    case 0:
      p = StandingPose(shape, root, yaw);
      break;
    case 1:
      p = ScarecrowPose(shape, root, yaw);
      break;
    default: {  // pointing forward with one arm, the other hanging
      p = StandingPose(shape, root, yaw);
      const int sh = which(rng) % 2 == 0 ? kDofRightShoulderAzimuth : kDofLeftShoulderAzimuth;
      p.dof[sh] = M_PI / 2;
      p.dof[sh + 1] = M_PI / 2;
    }
  }
  return p;
}

BodyPose TurnedPose(const BodyShape& shape, const BodyPose& current, double yaw) {
  const PosedBody body = PoseBody(shape, current);
  BodyPose next = current;
  next.dof[kDofYaw] = yaw;
  next.dof[kDofWaistZ] = 0;
  // Turned about the trunk's axis (the lower body's ellipsoid stays where
  // the silhouettes put it; the spine lies spine_depth_m behind it).
  const Vector2d trunk = body.segments[kLowerBody].center.head<2>();
  const Vector2d moved = PoseBody(shape, next).segments[kLowerBody].center.head<2>();
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
    SetArmDirections(shape, &next, a.segment, upper.normalized(), fore.normalized());
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

void CapRise(const BodyShape& shape, double max_rise_m, BodyPose* pose) {
  pose->dof[kDofZ] = std::min(pose->dof[kDofZ], shape.waist_height_m + max_rise_m);
}

BodyPose RandomWalkProposal(const BodyPose& current,
                            const BodyPose& previous,
                            double k,
                            const PoseTrackerOptions& options,
                            std::normal_distribution<double>& n01,
                            std::mt19937_64& rng) {
  BodyPose next = current;
  // Random walk with velocity (thesis 6.3.2), capped.
  for (int d = 0; d < kDofCount; ++d) {
    double v = current.dof[d] - previous.dof[d];
    if (IsAngleDof(d)) v = WrapAngle(v);
    const double cap = d < kDofYaw ? options.max_step_m : options.max_step_rad;
    next.dof[d] += options.velocity_damping * std::clamp(v, -cap, cap);
  }
  next.dof[kDofX] += k * options.sigma_position_m * n01(rng);
  next.dof[kDofY] += k * options.sigma_position_m * n01(rng);
  next.dof[kDofZ] += 0.3 * k * options.sigma_position_m * n01(rng);
  next.dof[kDofYaw] += k * options.sigma_yaw_rad * n01(rng);
  // The body's pitch and roll stay as they are (zero): the legs' ellipsoid
  // says little about them, and bowing or leaning is the waist's.
  for (int d : {kDofWaistZ, kDofWaistX, kDofWaistY, kDofNeckAzimuth, kDofNeckZenith}) {
    next.dof[d] += k * options.sigma_torso_rad * n01(rng);
  }
  for (int d : {kDofRightShoulderAzimuth, kDofRightShoulderZenith, kDofLeftShoulderAzimuth,
                kDofLeftShoulderZenith, kDofRightElbowAzimuth, kDofRightElbowZenith,
                kDofLeftElbowAzimuth, kDofLeftElbowZenith}) {
    next.dof[d] += k * options.sigma_arm_rad * n01(rng);
  }
  next.dof[kDofRightShoulderTwist] = next.dof[kDofLeftShoulderTwist] = 0.0;
  return next;
}

BodyPose BodyPositionProposal(const BodyPose& current,
                              const ProposalContext& context,
                              std::normal_distribution<double>& n01,
                              std::mt19937_64& rng) {
  BodyPose next = current;
  // Body position (thesis 6.3.2): the x and y of a random 3D torso axis
  // point (the trunk's middle, the waist spine_depth_m behind it), else
  // the voxel hull's root; while the user walks, the heading from the
  // hull's motion (people face where they walk).
  if (context.walking)
    next.dof[kDofYaw] = YawFacing(context.velocity_xy.normalized()) + 0.1 * n01(rng);
  const Vector2d noise(0.02 * n01(rng), 0.02 * n01(rng));
  if (!context.torso_xy.empty()) {
    std::uniform_int_distribution<size_t> pick(0, context.torso_xy.size() - 1);
    const Vector2d xy = context.torso_xy[pick(rng)] + noise -
                        context.shape.spine_depth_m * FacingDirection(next.dof[kDofYaw]);
    next.dof[kDofX] = xy.x();
    next.dof[kDofY] = xy.y();
  } else {
    PlaceRoot(context.shape, &next, context.features.placement->root.head<2>() + noise);
  }
  // Off the floor (a jump): the waist as high above its standing height as
  // the hull's lowest part above the floor.
  if (context.floor_gap_m > 0) {
    next.dof[kDofZ] = context.shape.waist_height_m + context.floor_gap_m + 0.02 * n01(rng);
  }
  return next;
}

BodyPose ProposeParticle(const BodyPose& current,
                         const BodyPose& previous,
                         double dt,
                         const ProposalContext& context,
                         std::mt19937_64& rng) {
  const PoseTrackerOptions& options = context.options;
  const double total = options.p_random_walk + options.p_body_position + options.p_arm_direction +
                       options.p_default_pose + options.p_posture;
  std::uniform_real_distribution<double> u(0.0, total);
  const double choice = u(rng);
  std::normal_distribution<double> n01(0.0, 1.0);
  const double k = std::sqrt(std::max(dt, 1e-3) * 30.0);
  BodyPose next = current;
  const double flip_or_turn = u(rng);
  if (flip_or_turn < options.p_turn * total && !context.walking && !context.entering) {
    // Turned (see PoseTrackerOptions::p_turn); not while walking or entering,
    // where the heading is the walk's.
    const double yaw = u(rng) < 0.5 * total ? YawFacing(context.facing_xy) + 0.15 * n01(rng)
                                            : current.dof[kDofYaw] + 0.8 * n01(rng);
    next = TurnedPose(context.shape, current, yaw);
  } else if (flip_or_turn < (options.p_turn + options.p_flip) * total) {
    // Front/back flip (silhouettes barely tell them apart): turned half way
    // round with the arms swapped so the silhouettes stay nearly the same;
    // the heading priors and raised arms' joint limits decide.
    next = FlippedPose(current);
  } else if (context.lost && u(rng) < 0.5 * total) {
    // Lost (the best particle explained the silhouettes poorly last frame):
    // half the particles restart from default poses where the hull is,
    // facing the screen (thesis 6.6: recovery within 2-3 frames).
    BodyPose facing = current;
    facing.dof[kDofYaw] = YawFacing(context.facing_xy) + 0.3 * n01(rng);
    next = DefaultPoseProposal(facing, context, rng);
  } else if (choice < options.p_random_walk) {
    next = RandomWalkProposal(current, previous, k, options, n01, rng);
  } else if (choice < options.p_random_walk + options.p_body_position) {
    next = BodyPositionProposal(current, context, n01, rng);
  } else if (choice < options.p_random_walk + options.p_body_position + options.p_arm_direction) {
    next = ArmDirectionProposal(current, context, rng);
  } else if (options.p_posture <= 0 || choice < options.p_random_walk + options.p_body_position +
                                                   options.p_arm_direction + options.p_default_pose) {
    next = DefaultPoseProposal(current, context, rng);
  } else {
    // The posture proposal; the random walk where there is no posture or
    // the particle already holds it.
    std::optional<BodyPose> moved;
    if (context.posture) moved = PostureProposal(current, context.shape, *context.posture, rng);
    next = moved ? *moved : RandomWalkProposal(current, previous, k, options, n01, rng);
  }
  // While the user walks, a particle facing more than 90 deg away from the
  // walking direction is turned to it (people do not walk backwards onto a
  // stage; silhouettes cannot tell front from back).
  // An entering user (first seen half in view) likewise faces the stage's
  // centre until the walk itself is seen.
  if (context.walking || context.entering) {
    const double heading =
        YawFacing(context.walking ? context.velocity_xy.normalized() : context.walk_dir);
    if (std::cos(next.dof[kDofYaw] - heading) < 0) next = FlippedPose(next);
  }
  ClampToJointLimits(&next);
  CapRise(context.shape, options.max_rise_m + context.extra_rise_m, &next);
  return next;
}

std::vector<double> WeighParticles(const std::vector<BodyPose>& particles, const PoseScore& score) {
  const int n = static_cast<int>(particles.size());
  std::vector<double> log_likelihood(n);
  // Ctrl-C is honoured within a frame: workers stop scoring (an exception
  // must not leave a worker thread) and the caller's thread throws.
  cv::parallel_for_(cv::Range(0, n), [&](const cv::Range& r) {
    for (int i = r.start; i < r.end && !CancelRequested(); ++i) {
      log_likelihood[i] = score(particles[i]);
    }
  });
  ThrowIfCancelled();
  return log_likelihood;
}

void RefineParticles(const BodyShape& shape,
                     const std::vector<IcpView>& icp_views,
                     const PoseTrackerOptions& options,
                     const PoseScore& score,
                     std::mt19937_64& rng,
                     std::vector<BodyPose>* particles,
                     std::vector<double>* log_likelihood,
                     double extra_rise_m) {
  std::vector<BodyPose>& proposed = *particles;
  const int n = static_cast<int>(proposed.size());
  const int refine = static_cast<int>(std::round(options.refine_fraction * n));
  if (refine > 0 && options.icp.iterations > 0) {
    std::vector<int> order(n);
    std::iota(order.begin(), order.end(), 0);
    std::shuffle(order.begin(), order.end(), rng);
    order.resize(refine);
    std::vector<BodyPose> refined(refine);
    std::vector<double> refined_ll(refine);
    cv::parallel_for_(cv::Range(0, refine), [&](const cv::Range& r) {
      for (int j = r.start; j < r.end && !CancelRequested(); ++j) {
        refined[j] = RefineIcp(shape, proposed[order[j]], icp_views, options.icp);
        CapRise(shape, options.max_rise_m + extra_rise_m, &refined[j]);
        refined_ll[j] = score(refined[j]);
      }
    });
    ThrowIfCancelled();
    for (int j = 0; j < refine; ++j) {
      if (refined_ll[j] > (*log_likelihood)[order[j]]) {
        proposed[order[j]] = refined[j];
        (*log_likelihood)[order[j]] = refined_ll[j];
      }
    }
  }
}

int BestParticle(const std::vector<double>& log_likelihood) {
  return static_cast<int>(std::max_element(log_likelihood.begin(), log_likelihood.end()) -
                          log_likelihood.begin());
}

void ResampleSystematic(const std::vector<BodyPose>& proposed,
                        const std::vector<double>& log_likelihood,
                        double max_ll,
                        std::mt19937_64& rng,
                        std::vector<BodyPose>* particles,
                        std::vector<BodyPose>* previous) {
  // Resampling (systematic), carrying each particle's previous state along
  // for the velocity.
  const int n = static_cast<int>(proposed.size());
  std::vector<double> cumulative(n);
  double sum = 0;
  for (int i = 0; i < n; ++i) {
    sum += std::exp(log_likelihood[i] - max_ll);
    cumulative[i] = sum;
  }
  std::uniform_real_distribution<double> u0(0.0, sum / n);
  double pointer = u0(rng);
  std::vector<BodyPose> next(n), next_previous(n);
  const std::vector<BodyPose>& before = *particles;
  int i = 0;
  for (int j = 0; j < n; ++j) {
    while (i < n - 1 && cumulative[i] < pointer) ++i;
    next[j] = proposed[i];
    next_previous[j] = i < static_cast<int>(before.size()) ? before[i] : proposed[i];
    pointer += sum / n;
  }
  *particles = std::move(next);
  *previous = std::move(next_previous);
}

}  // namespace irbench
