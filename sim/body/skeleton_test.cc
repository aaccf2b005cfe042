#include "sim/body/skeleton.h"

#include <gtest/gtest.h>

#include "sim/body/avatar.h"

namespace irbench {
namespace {

TEST(SkeletonTest, BindPoseIsIdentityTransformsAtBindPositions) {
  const Avatar avatar = BuildTubeAvatar({});
  const JointTransforms t = ForwardKinematics(avatar.skeleton, Pose());
  for (int j = 0; j < kJointCount; ++j) {
    EXPECT_TRUE(t[j].translation().isApprox(avatar.skeleton.bind_position[j], 1e-12)) << JointName(j);
    EXPECT_TRUE(t[j].linear().isIdentity(1e-12));
  }
}

TEST(SkeletonTest, RotationConventionsOfTheDocs) {
  const Avatar avatar = BuildTubeAvatar({});
  const auto& bind = avatar.skeleton.bind_position;
  const double upper_arm = (bind[kRightElbow] - bind[kRightShoulder]).norm();
  Pose pose;
  pose.local_rotation[kRightShoulder] = RotationZXYDeg({0, 90, 0});   // right arm down
  pose.local_rotation[kLeftShoulder] = RotationZXYDeg({0, -90, 0});   // left arm down
  pose.local_rotation[kRightElbow] = RotationZXYDeg({0, 0, 90});      // forearm forward
  const JointTransforms t = ForwardKinematics(avatar.skeleton, pose);
  const Eigen::Vector3d r_upper = t[kRightElbow].translation() - t[kRightShoulder].translation();
  EXPECT_TRUE(r_upper.isApprox(Eigen::Vector3d(0, 0, -upper_arm), 1e-9)) << r_upper.transpose();
  const Eigen::Vector3d l_upper = t[kLeftElbow].translation() - t[kLeftShoulder].translation();
  EXPECT_TRUE(l_upper.isApprox(Eigen::Vector3d(0, 0, -upper_arm), 1e-9)) << l_upper.transpose();
  const Eigen::Vector3d r_fore = t[kRightWrist].translation() - t[kRightElbow].translation();
  EXPECT_NEAR(r_fore.normalized().y(), 1.0, 1e-9);  // forward is +y
}

TEST(SkeletonTest, ForwardKinematicsPreservesBoneLengths) {
  const Avatar avatar = BuildTubeAvatar({});
  Pose pose;
  pose.root_offset = {0.3, -0.2, -0.1};
  for (int j = 0; j < kJointCount; ++j) pose.local_rotation[j] = RotationZXYDeg({7.0 * j, -5.0 * j, 3.0 * j});
  const JointTransforms t = ForwardKinematics(avatar.skeleton, pose);
  for (int j = 1; j < kJointCount; ++j) {
    const int p = JointParent(j);
    const double bind_len = (avatar.skeleton.bind_position[j] - avatar.skeleton.bind_position[p]).norm();
    EXPECT_NEAR((t[j].translation() - t[p].translation()).norm(), bind_len, 1e-12) << JointName(j);
  }
}

}  // namespace
}  // namespace irbench
