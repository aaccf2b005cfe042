#pragma once
// The canonical skeleton every avatar is posed on, and forward kinematics.
//
// Bind pose: a T-pose standing at the world origin on the floor (z = 0), facing
// +y, so the person's right is +x. Every joint frame is aligned with the world
// axes in the bind pose; a joint's local rotation is applied in that frame.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <optional>
#include <string>
#include <vector>

namespace irbench {

enum Joint : int {
  kPelvis = 0,
  kSpine,
  kChest,
  kNeck,
  kHead,
  kRightClavicle,
  kRightShoulder,
  kRightElbow,
  kRightWrist,
  kLeftClavicle,
  kLeftShoulder,
  kLeftElbow,
  kLeftWrist,
  kRightHip,
  kRightKnee,
  kRightAnkle,
  kLeftHip,
  kLeftKnee,
  kLeftAnkle,
  kJointCount
};

const char* JointName(int joint);
int JointParent(int joint);  // -1 for the pelvis
std::optional<int> JointFromName(const std::string& name);

using JointTransforms = std::array<Eigen::Isometry3d, kJointCount>;

struct Skeleton {
  // Joint centres in the bind pose, world metres.
  std::array<Eigen::Vector3d, kJointCount> bind_position;
};

struct Pose {
  // Pelvis displacement from its bind position, world metres.
  Eigen::Vector3d root_offset = Eigen::Vector3d::Zero();
  // Local rotations; the pelvis's is the whole body's orientation.
  std::array<Eigen::Quaterniond, kJointCount> local_rotation;
  Pose() { local_rotation.fill(Eigen::Quaterniond::Identity()); }
};

// world_from_joint for every joint.
JointTransforms ForwardKinematics(const Skeleton& skeleton, const Pose& pose);

// Rotation from degrees in the thesis's ZXY order: R = Rz(z) * Rx(x) * Ry(y).
Eigen::Quaterniond RotationZXYDeg(const Eigen::Vector3d& xyz_deg);

// A point fixed to a joint's frame: the truth points that are not joint
// centres (head centre, hand tips).
struct BoneMarker {
  std::string name;
  int joint = kPelvis;
  Eigen::Vector3d offset_in_joint = Eigen::Vector3d::Zero();
};

}  // namespace irbench
