#include "tracker/pose/pose_tracker_options.h"

#include <stdexcept>

#include "common/error.h"

namespace irbench {

void PoseTrackerOptions::Check() const {
  if (particles < 1) throw InputError("", "pose.particles", "must be at least 1");
  observation.Check();
  icp.Check();
  for (double p : {p_random_walk, p_body_position, p_arm_direction, p_default_pose}) {
    if (!(p >= 0)) throw InputError("", "pose.proposal_probabilities", "must be non-negative");
  }
  if (!(p_flip >= 0 && p_flip <= 1)) throw InputError("", "pose.p_flip", "must be in [0, 1]");
  if (!(p_turn >= 0 && p_flip + p_turn <= 1))
    throw InputError("", "pose.p_turn", "must be in [0, 1 - p_flip]");
  if (!(p_random_walk + p_body_position + p_arm_direction + p_default_pose > 0)) {
    throw InputError("", "pose.proposal_probabilities", "must not all be zero");
  }
  for (double s : {sigma_position_m, sigma_yaw_rad, sigma_torso_rad, sigma_arm_rad, max_step_rad,
                   max_step_m}) {
    if (!(s >= 0)) throw InputError("", "pose.noise_and_caps", "must be non-negative");
  }
  if (!(velocity_damping >= 0 && velocity_damping <= 1)) {
    throw InputError("", "pose.velocity_damping", "must be in [0, 1]");
  }
  if (!(refine_fraction >= 0 && refine_fraction <= 1)) {
    throw InputError("", "pose.refine_fraction", "must be in [0, 1]");
  }
  if (!(min_overlap >= 0 && min_overlap <= 1))
    throw InputError("", "pose.min_overlap", "must be in [0, 1]");
  if (!(rest_max_log_overlap_loss >= 0))
    throw InputError("", "pose.rest_max_log_overlap_loss", "must be non-negative");
  if (!(max_rise_m >= 0)) throw InputError("", "pose.max_rise_m", "must be non-negative");
  if (!(min_floor_gap_m > 0)) throw InputError("", "pose.min_floor_gap_m", "must be positive");
  if (!(max_tiptoe_m >= 0)) throw InputError("", "pose.max_tiptoe_m", "must be non-negative");
  if (!(tiptoe_radius_m > 0)) throw InputError("", "pose.tiptoe_radius_m", "must be positive");
  if (!(rest_seen_max_angle_deg >= 0 && rest_seen_max_angle_deg <= 180)) {
    throw InputError("", "pose.rest_seen_max_angle_deg", "must be in [0, 180]");
  }
  if (!(rest_lifted_angle_deg >= 0 && rest_lifted_angle_deg <= 180)) {
    throw InputError("", "pose.rest_lifted_angle_deg", "must be in [0, 180]");
  }
  if (!(rest_held_min_gain >= 0))
    throw InputError("", "pose.rest_held_min_gain", "must be non-negative");
  if (!(rest_lifted_memory_s >= 0))
    throw InputError("", "pose.rest_lifted_memory_s", "must be non-negative");
  if (rest_lifted_angle_deg < rest_seen_max_angle_deg) {
    throw InputError("", "pose.rest_lifted_angle_deg",
                     "must be at least pose.rest_seen_max_angle_deg");
  }
  hull_head.Check();
  hull_legs.Check();
  if (!(feet_memory_s > 0)) throw InputError("", "pose.feet_memory_s", "must be positive");
  if (!(root_offset_smoothing_s > 0)) throw InputError("", "pose.root_offset_smoothing_s", "must be positive");
  if (!(root_offset_memory_s > 0)) throw InputError("", "pose.root_offset_memory_s", "must be positive");
  if (!(feet_min_m >= 0)) throw InputError("", "pose.feet_min_m", "must be non-negative");
  if (!(step_max_speed_mps >= 0)) throw InputError("", "pose.step_max_speed_mps", "must be non-negative");
  if (!(step_feet_angle_deg >= 0 && step_feet_angle_deg <= 180))
    throw InputError("", "pose.step_feet_angle_deg", "must be in [0, 180]");
  if (!(step_back_max_s >= 0)) throw InputError("", "pose.step_back_max_s", "must be non-negative");
  if (!(heading_settled_s >= 0)) throw InputError("", "pose.heading_settled_s", "must be non-negative");
  if (height_frames < 1) throw InputError("", "pose.height_frames", "must be at least 1");
  if (!(height_max_lean_deg > 0 && height_max_lean_deg <= 90))
    throw InputError("", "pose.height_max_lean_deg", "must be in (0, 90]");
  if (!(height_min_waist >= 0 && height_min_waist <= 1))
    throw InputError("", "pose.height_min_waist", "must be in [0, 1]");
  if (!(height_top_match > 0)) throw InputError("", "pose.height_top_match", "must be positive");
  if (arm_thickness_frames < 0)
    throw InputError("", "pose.arm_thickness_frames", "must be non-negative");
  if (arm_thickness_min_points < 1)
    throw InputError("", "pose.arm_thickness_min_points", "must be at least 1");
  if (!(arm_reference_diameter > 0))
    throw InputError("", "pose.arm_reference_diameter", "must be positive");
  if (!(max_arm_thickness >= 1))
    throw InputError("", "pose.max_arm_thickness", "must be at least 1");
  if (shoulder_samples < 0) throw InputError("", "pose.shoulder_samples", "must be non-negative");
  if (shoulder_min_samples < 1) throw InputError("", "pose.shoulder_min_samples", "must be at least 1");
  if (!(shoulder_max_spread_m > 0))
    throw InputError("", "pose.shoulder_max_spread_m", "must be positive");
  if (!(shoulder_girth_bias_m >= 0 && shoulder_girth_bias_m <= 0.2)) {
    throw InputError("", "pose.shoulder_girth_bias_m", "must be in 0..0.2 m");
  }
  if (!(shoulder_bias_girth >= 0.5 && shoulder_bias_girth <= 3)) {
    throw InputError("", "pose.shoulder_bias_girth", "must be in 0.5..3");
  }
  if (!(walk_memory_s >= 0)) throw InputError("", "pose.walk_memory_s", "must be non-negative");
}

}  // namespace irbench
