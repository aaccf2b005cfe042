#include "sim/body/skeleton.h"

#include <cmath>

namespace irbench {
namespace {

constexpr const char* kNames[kJointCount] = {
    "pelvis",         "spine",       "chest",        "neck",           "head",
    "right_clavicle", "right_shoulder", "right_elbow", "right_wrist",   "left_clavicle",
    "left_shoulder",  "left_elbow",  "left_wrist",   "right_hip",      "right_knee",
    "right_ankle",    "left_hip",    "left_knee",    "left_ankle"};

constexpr int kParents[kJointCount] = {
    -1,       kPelvis,        kSpine,        kChest,          kNeck,
    kChest,   kRightClavicle, kRightShoulder, kRightElbow,    kChest,
    kLeftClavicle, kLeftShoulder, kLeftElbow, kPelvis,        kRightHip,
    kRightKnee, kPelvis,      kLeftHip,      kLeftKnee};

}  // namespace

const char* JointName(int joint) { return kNames[joint]; }
int JointParent(int joint) { return kParents[joint]; }

std::optional<int> JointFromName(const std::string& name) {
  for (int j = 0; j < kJointCount; ++j) {
    if (name == kNames[j]) return j;
  }
  return std::nullopt;
}

JointTransforms ForwardKinematics(const Skeleton& skeleton, const Pose& pose) {
  JointTransforms world_from_joint;
  for (int j = 0; j < kJointCount; ++j) {
    // Parents precede children in the enum, so one pass suffices.
    const int parent = kParents[j];
    Eigen::Isometry3d parent_from_joint = Eigen::Isometry3d::Identity();
    parent_from_joint.linear() = pose.local_rotation[j].normalized().toRotationMatrix();
    if (parent < 0) {
      parent_from_joint.translation() = skeleton.bind_position[j] + pose.root_offset;
      world_from_joint[j] = parent_from_joint;
    } else {
      parent_from_joint.translation() =
          skeleton.bind_position[j] - skeleton.bind_position[parent];
      world_from_joint[j] = world_from_joint[parent] * parent_from_joint;
    }
  }
  return world_from_joint;
}

Eigen::Quaterniond RotationZXYDeg(const Eigen::Vector3d& xyz_deg) {
  const Eigen::Vector3d r = xyz_deg * M_PI / 180.0;
  return Eigen::AngleAxisd(r.z(), Eigen::Vector3d::UnitZ()) *
         Eigen::AngleAxisd(r.x(), Eigen::Vector3d::UnitX()) *
         Eigen::AngleAxisd(r.y(), Eigen::Vector3d::UnitY());
}

}  // namespace irbench
