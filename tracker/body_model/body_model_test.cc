#include "tracker/body_model/body_model.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace irbench {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;

TEST(BodyModel, StandingPoseHasTheProportionsItWasScaledTo) {
  const BodyShape shape = BodyShape::FromHeight(1.80);
  const PosedBody body = PoseBody(shape, StandingPose(shape, Vector2d(0.3, -0.2), 0.0));
  EXPECT_NEAR((body.joints[kModelRoot] - Vector3d(0.3, -0.2, 0)).norm(), 0, 1e-12);
  EXPECT_NEAR(body.joints[kModelWaist].z(), 0.600 * 1.80, 1e-12);
  EXPECT_NEAR(body.joints[kModelNeck].z(), 0.818 * 1.80, 1e-12);
  EXPECT_NEAR(body.joints[kModelHead].z(), 0.935 * 1.80, 1e-12);
  // The spine's joints lie behind the trunk's middle (facing +y), the ankles
  // behind the waist: the root is the floor point under them.
  EXPECT_GT(shape.spine_depth_m, 0.01);
  EXPECT_GT(shape.ankle_setback_m, 0.01);
  for (int seg : {kLowerBody, kUpperBody, kHeadSegment}) {
    const Vector3d off = body.segments[seg].center - (seg == kHeadSegment ? body.joints[kModelNeck] : body.joints[kModelWaist]);
    EXPECT_NEAR(off.y(), shape.spine_depth_m, 1e-12) << BodySegmentName(seg);
    EXPECT_NEAR(off.x(), 0, 1e-12) << BodySegmentName(seg);
  }
  EXPECT_NEAR(body.joints[kModelRoot].y() - body.joints[kModelWaist].y(), -shape.ankle_setback_m, 1e-12);
  EXPECT_NEAR((body.joints[kModelHead] - body.segments[kHeadSegment].center).norm(), 0, 1e-12);
  // The head ellipsoid reaches the stature.
  EXPECT_NEAR(body.segments[kHeadSegment].center.z() + body.segments[kHeadSegment].radii.z(), 1.80, 0.01);
  // Facing +y, the right arm is on the +x side and hangs.
  EXPECT_GT(body.joints[kModelRightWrist].x(), body.joints[kModelRightShoulder].x());
  EXPECT_LT(body.joints[kModelLeftWrist].x(), body.joints[kModelLeftShoulder].x());
  EXPECT_LT(body.joints[kModelRightWrist].z(), body.joints[kModelRightElbow].z());
  EXPECT_NEAR((body.joints[kModelRightElbow] - body.joints[kModelRightShoulder]).norm(), shape.upper_arm_m, 1e-12);
  EXPECT_NEAR((body.joints[kModelLeftWrist] - body.joints[kModelLeftElbow]).norm(), shape.forearm_m, 1e-12);
  EXPECT_NEAR((body.joints[kModelLeftHandTip] - body.joints[kModelLeftElbow]).norm(), shape.forearm_m + shape.hand_m,
              1e-12);
}

// arm_thickness widens the arms' ellipsoids across, on top of the girth's
// square root, and changes nothing else: not their lengths, not the trunk,
// not a joint.
TEST(BodyModel, ArmThicknessWidensOnlyTheArmsAcross) {
  const BodyShape plain = BodyShape::FromHeight(1.80, 1.5);
  const BodyShape thick = BodyShape::FromHeight(1.80, 1.5, 1.25);
  EXPECT_EQ(plain.arm_thickness, 1.0);
  EXPECT_EQ(thick.arm_thickness, 1.25);
  for (int seg = 0; seg < kSegmentCount; ++seg) {
    const bool arm = seg == kRightUpperArm || seg == kRightLowerArm || seg == kLeftUpperArm || seg == kLeftLowerArm;
    const double across = arm ? 1.25 : 1.0;
    EXPECT_NEAR(thick.radii[seg].x(), across * plain.radii[seg].x(), 1e-12) << BodySegmentName(seg);
    EXPECT_NEAR(thick.radii[seg].y(), across * plain.radii[seg].y(), 1e-12) << BodySegmentName(seg);
    EXPECT_NEAR(thick.radii[seg].z(), plain.radii[seg].z(), 1e-12) << BodySegmentName(seg);
    EXPECT_NEAR(thick.center_along[seg], plain.center_along[seg], 1e-12) << BodySegmentName(seg);
  }
  // The arms' radius across is the girth's square root times arm_thickness
  // of the unwidened one.
  EXPECT_NEAR(thick.radii[kRightUpperArm].x(),
              std::sqrt(1.5) * 1.25 * BodyShape::FromHeight(1.80).radii[kRightUpperArm].x(), 1e-12);
  const BodyPose pose = ScarecrowPose(plain, Vector2d(0.1, 0.2), 0.4);
  const PosedBody a = PoseBody(plain, pose), b = PoseBody(thick, pose);
  for (int j = 0; j < kModelJointCount; ++j) EXPECT_NEAR((a.joints[j] - b.joints[j]).norm(), 0, 1e-12) << j;
}

TEST(BodyModel, ScarecrowArmsPointToThePersonsSidesWhateverTheYaw) {
  const BodyShape shape = BodyShape::FromHeight(1.70);
  for (double yaw : {0.0, 0.7, M_PI / 2, -2.5}) {
    const PosedBody body = PoseBody(shape, ScarecrowPose(shape, Vector2d::Zero(), yaw));
    const Vector3d right_of_person(std::cos(yaw), std::sin(yaw), 0);
    const Vector3d arm = (body.joints[kModelRightHandTip] - body.joints[kModelRightShoulder]).normalized();
    EXPECT_GT(arm.dot(right_of_person), 0.999) << yaw;
    const Vector3d left_arm = (body.joints[kModelLeftHandTip] - body.joints[kModelLeftShoulder]).normalized();
    EXPECT_GT(left_arm.dot(-right_of_person), 0.999) << yaw;
  }
}

TEST(BodyModel, AnglesAndDirectionsRoundTrip) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> az(-M_PI + 1e-3, M_PI - 1e-3), zen(0.01, M_PI - 0.01);
  for (int i = 0; i < 200; ++i) {
    for (double rest : {1.0, -1.0}) {
      for (bool mirror : {false, true}) {
        const double a = az(rng), z = zen(rng);
        const Vector2d back = AnglesFromDirection(DirectionFromAngles(a, z, rest, mirror), rest, mirror);
        EXPECT_NEAR(back[0], a, 1e-9);
        EXPECT_NEAR(back[1], z, 1e-9);
      }
    }
  }
}

// SetArmDirections is the inverse of the arm's forward kinematics for any
// body and waist rotation.
TEST(BodyModel, SetArmDirectionsPutsTheSegmentsAlongTheGivenDirections) {
  const BodyShape shape = BodyShape::FromHeight(1.75);
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int i = 0; i < 100; ++i) {
    BodyPose pose = StandingPose(shape, Vector2d(u(rng), u(rng)), M_PI * u(rng));
    pose.dof[kDofPitch] = 0.3 * u(rng);
    pose.dof[kDofWaistZ] = 0.5 * u(rng);
    pose.dof[kDofWaistX] = 0.3 * u(rng);
    for (int arm : {kRightUpperArm, kLeftUpperArm}) {
      const Vector3d upper = Vector3d(u(rng), u(rng), u(rng)).normalized();
      const Vector3d fore = Vector3d(u(rng), u(rng), u(rng)).normalized();
      SetArmDirections(shape, &pose, arm, upper, fore);
      const PosedBody body = PoseBody(shape, pose);
      const int shoulder = arm == kRightUpperArm ? kModelRightShoulder : kModelLeftShoulder;
      const Vector3d got_upper = (body.joints[shoulder + 1] - body.joints[shoulder]).normalized();
      const Vector3d got_fore = (body.joints[shoulder + 2] - body.joints[shoulder + 1]).normalized();
      EXPECT_GT(got_upper.dot(upper), 1 - 1e-9);
      EXPECT_GT(got_fore.dot(fore), 1 - 1e-9);
    }
  }
}

TEST(BodyModel, JointLimitsKeepAllowedPosesAndCapTheRest) {
  const BodyShape shape = BodyShape::FromHeight(1.75);
  BodyPose pose = ScarecrowPose(shape, Vector2d::Zero(), 0.3);
  pose.dof[kDofRightElbowZenith] = 1.0;
  const BodyPose before = pose;
  EXPECT_TRUE(ClampToJointLimits(&pose));
  for (int d = 0; d < kDofCount; ++d) EXPECT_NEAR(pose.dof[d], before.dof[d], 1e-12) << BodyDofName(d);

  // The forearm folded back on itself, the upper arm straight behind the back.
  pose.dof[kDofRightElbowZenith] = 3.0;
  pose.dof[kDofLeftShoulderAzimuth] = -M_PI / 2;
  pose.dof[kDofLeftShoulderZenith] = M_PI / 2;
  EXPECT_FALSE(ClampToJointLimits(&pose));
  EXPECT_NEAR(pose.dof[kDofRightElbowZenith], 150.0 * M_PI / 180.0, 1e-12);
  const Vector3d left = DirectionFromAngles(pose.dof[kDofLeftShoulderAzimuth], pose.dof[kDofLeftShoulderZenith], -1,
                                            false);
  EXPECT_NEAR(std::acos(left.dot(Vector3d(0.86, 0.51, 0).normalized())), 120.0 * M_PI / 180.0, 1e-9);
  EXPECT_TRUE(ClampToJointLimits(&pose));  // now inside
}

// The forearm's component along the elbow's forward axis: the body's forward
// (y) carried by the minimal rotation that takes straight down to the upper
// arm, computed here from the posed joints.
double ForearmForward(const PosedBody& body, int shoulder_joint) {
  const Eigen::Matrix3d upper = body.frames[kUpperBody].linear();
  const Vector3d u = upper.transpose() * (body.joints[shoulder_joint + 1] - body.joints[shoulder_joint]).normalized();
  const Vector3d f = upper.transpose() * (body.joints[shoulder_joint + 2] - body.joints[shoulder_joint + 1]).normalized();
  const Vector3d forward = Eigen::Quaterniond::FromTwoVectors(Vector3d(0, 0, -1), u) * Vector3d::UnitY();
  return f.dot(forward);
}

TEST(BodyModel, TheElbowDoesNotBendBackwards) {
  const BodyShape shape = BodyShape::FromHeight(1.75);
  // A hanging right arm, the forearm bent 60 deg straight back: turned to
  // the edge where it points 0.1 of its length backwards, its bend kept.
  BodyPose pose = StandingPose(shape, Vector2d::Zero(), 0.4);
  pose.dof[kDofRightShoulderZenith] = 0.0;
  pose.dof[kDofRightElbowAzimuth] = -M_PI / 2 + 0.1;
  pose.dof[kDofRightElbowZenith] = M_PI / 3;
  EXPECT_FALSE(ClampToJointLimits(&pose));
  EXPECT_NEAR(ForearmForward(PoseBody(shape, pose), kModelRightShoulder), -0.1, 1e-9);
  EXPECT_NEAR(pose.dof[kDofRightElbowZenith], M_PI / 3, 1e-12);
  // The nearer edge: bent back and out goes out, back and in goes in.
  EXPECT_NEAR(pose.dof[kDofRightElbowAzimuth], -std::asin(0.1 / std::sin(M_PI / 3)), 1e-12);
  pose.dof[kDofRightElbowAzimuth] = -M_PI / 2 - 0.1;
  EXPECT_FALSE(ClampToJointLimits(&pose));
  EXPECT_NEAR(pose.dof[kDofRightElbowAzimuth], -M_PI + std::asin(0.1 / std::sin(M_PI / 3)), 1e-12);
  // Bent forward, or barely bent whichever way: allowed.
  pose.dof[kDofRightElbowAzimuth] = M_PI / 2;
  EXPECT_TRUE(ClampToJointLimits(&pose));
  pose.dof[kDofRightElbowAzimuth] = -M_PI / 2;
  pose.dof[kDofRightElbowZenith] = 0.09;
  EXPECT_TRUE(ClampToJointLimits(&pose));

  // Brute force over arms anywhere, twisted or not, both sides: after the
  // caps no forearm points more than 0.1 backwards, and a pose inside keeps
  // every angle.
  std::mt19937 rng(11);
  // Drawn inside the other caps (the upper arm's cone, the elbow's 150 deg).
  std::uniform_real_distribution<double> angle(-M_PI, M_PI), zenith(0.0, 2.6), twist(-0.6, 0.6);
  const Vector3d cone_centre = Vector3d(0.86, 0.51, 0).normalized();
  int capped = 0;
  for (int i = 0; i < 4000; ++i) {
    BodyPose p = StandingPose(shape, Vector2d::Zero(), angle(rng));
    for (int dof : {kDofRightShoulderAzimuth, kDofLeftShoulderAzimuth}) {
      do {
        p.dof[dof] = angle(rng);
        p.dof[dof + 1] = std::acos(std::uniform_real_distribution<double>(-0.99, 1.0)(rng));
      } while (DirectionFromAngles(p.dof[dof], p.dof[dof + 1], -1, false).dot(cone_centre) <
               std::cos(120.0 * M_PI / 180.0));
      p.dof[dof + 2] = twist(rng);
    }
    for (int dof : {kDofRightElbowAzimuth, kDofLeftElbowAzimuth}) {
      p.dof[dof] = angle(rng);
      p.dof[dof + 1] = zenith(rng);
    }
    const double right = ForearmForward(PoseBody(shape, p), kModelRightShoulder);
    const double left = ForearmForward(PoseBody(shape, p), kModelLeftShoulder);
    const BodyPose before = p;
    const bool inside = ClampToJointLimits(&p);
    const PosedBody body = PoseBody(shape, p);
    EXPECT_GE(ForearmForward(body, kModelRightShoulder), -0.1 - 1e-9);
    EXPECT_GE(ForearmForward(body, kModelLeftShoulder), -0.1 - 1e-9);
    EXPECT_EQ(inside, right >= -0.1 - 1e-12 && left >= -0.1 - 1e-12) << i;
    if (!inside) ++capped;
    for (int d = 0; d < kDofCount; ++d) {
      if (d == kDofRightElbowAzimuth || d == kDofLeftElbowAzimuth) continue;
      EXPECT_NEAR(p.dof[d], before.dof[d], 1e-12) << BodyDofName(d);
    }
    if (inside) {
      EXPECT_NEAR(p.dof[kDofRightElbowAzimuth], before.dof[kDofRightElbowAzimuth], 1e-12);
      EXPECT_NEAR(p.dof[kDofLeftElbowAzimuth], before.dof[kDofLeftElbowAzimuth], 1e-12);
    }
  }
  EXPECT_GT(capped, 500);  // the draw does reach the forbidden range
}

}  // namespace
}  // namespace irbench

namespace irbench {
namespace {

// YawFacing turns the body to face a direction: the person's right shoulder
// is then on their right (facing = up x (right - left)).
TEST(BodyModel, YawFacingFacesTheDirection) {
  const BodyShape shape = BodyShape::FromHeight(1.75);
  for (double a = -3.0; a < 3.2; a += 0.5) {
    const Eigen::Vector2d dir(std::cos(a), std::sin(a));
    const PosedBody body = PoseBody(shape, StandingPose(shape, Eigen::Vector2d(0.3, -0.2), YawFacing(dir)));
    const Eigen::Vector3d across = body.joints[kModelRightShoulder] - body.joints[kModelLeftShoulder];
    const Eigen::Vector3d facing = Eigen::Vector3d::UnitZ().cross(across).normalized();
    EXPECT_NEAR(facing.x(), dir.x(), 1e-9) << a;
    EXPECT_NEAR(facing.y(), dir.y(), 1e-9) << a;
  }
}

}  // namespace
}  // namespace irbench
