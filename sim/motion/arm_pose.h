#pragma once
// One arm's pose for the motion library (library.cc): built from
// directions, angles or a wrist target, the thesis's five posture atoms
// (docs/motion.md) and blends of them.

#include <Eigen/Geometry>
#include <array>

#include "sim/body/skeleton.h"
#include "sim/motion/library.h"

namespace irbench {

// One arm: the shoulder's rotation in the chest frame (its local rotation, the
// clavicle staying at its bind rotation) and the elbow's flexion.
struct ArmPose {
  Eigen::Quaterniond shoulder = Eigen::Quaterniond::Identity();
  double elbow_deg = 0;
};

Eigen::Vector3d BindArmDir(int side);

// Upper arm along d_u, forearm along d_f (chest frame), bending as a hinge.
ArmPose ArmFromDirections(int side, const Eigen::Vector3d& d_u, const Eigen::Vector3d& d_f);

// Arm direction by azimuth (0: straight out to the side, 90: forward) and
// elevation (0: horizontal, 90: up), the forearm bent by `elbow` degrees
// towards `bend` (default: up, or forward when the arm points up or down).
ArmPose ArmAngles(int side, double az, double el, double elbow = 0,
                  const Eigen::Vector3d& bend = Eigen::Vector3d::Zero());

// The resting arm: hanging, slightly away from the body, the elbow a little bent.
ArmPose RestArm(int side, const MotionStyle& style);

// From `a` (w 0) to `b` (w 1): the shoulder slerped, the elbow linear.
ArmPose Blend(const ArmPose& a, const ArmPose& b, double w);

// Two-bone reach: the wrist at `wrist` (chest frame, relative to the
// shoulder), the elbow bending away from `pole`.
ArmPose ArmReach(int side, const Skeleton& sk, const Eigen::Vector3d& wrist, const Eigen::Vector3d& pole);

// The five atom postures of one arm, A0 (rest) to A4.
ArmPose Atom(int atom, int side, const MotionStyle& style);

// A blend of the atoms (the library's `posture` with weights): thesis
// 5.1.1's decomposition read the other way, the rest posture A0 plus each
// weight times its atom's departure from it. The shoulder's rotation is the
// weighted mean of the atoms' rotations (their quaternions summed, each on
// the rest's side, and normalised: for two atoms a point on the slerp's arc,
// the midpoint at equal weights), the elbow's angle the weighted mean; A0
// takes what the weights (A0..A4) leave of 1, and weights summing over 1
// are scaled to 1.
ArmPose AtomBlend(std::array<double, 5> weights, int side, const MotionStyle& style);

}  // namespace irbench
