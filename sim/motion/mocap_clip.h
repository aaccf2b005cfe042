#pragma once
// A motion-capture clip in its own skeleton, units and axes, after forward
// kinematics: what BVH and ASF/AMC files both become before retargeting
// (retarget.h) onto the canonical skeleton.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <filesystem>
#include <string>
#include <vector>

namespace irbench {

struct MocapClip {
  std::string name;
  std::filesystem::path file;
  // The naming convention the joint names follow ("mb", "daz", "3dsmax",
  // "cmu", "irbench"), found by retarget.h from the names; empty if unknown.
  std::string convention;
  // Joints, parents before children. Leaf ends (BVH "End Site", an ASF bone's
  // tip) are joints too, named "<parent name>_end", with no rotation of their own.
  std::vector<std::string> joint_names;
  std::vector<int> parent;  // -1 for the root
  // World position of every joint with every rotation channel zero (the file's
  // rest pose), in file units and axes.
  std::vector<Eigen::Vector3d> rest_position;
  double frame_time = 1.0 / 120.0;  // seconds
  // Metres per file unit when the format says so (ASF :units length); 0 if
  // unknown. Retargeting does not need it (it scales by leg length).
  double metres_per_unit = 0;

  struct Frame {
    // World position of every joint, file units and axes.
    std::vector<Eigen::Vector3d> position;
    // World rotation of every joint's frame relative to its rest orientation
    // (for BVH, the product of the local rotations down the chain).
    std::vector<Eigen::Quaterniond> rotation;
  };
  std::vector<Frame> frames;

  // Index of a joint by exact name, or -1.
  int FindJoint(const std::string& joint_name) const {
    for (size_t i = 0; i < joint_names.size(); ++i) {
      if (joint_names[i] == joint_name) return static_cast<int>(i);
    }
    return -1;
  }
  double Duration() const { return frames.empty() ? 0.0 : (frames.size() - 1) * frame_time; }
};

}  // namespace irbench
