#include <gtest/gtest.h>

#include <cmath>

#include "sim/body/avatar.h"
#include "sim/motion/keyframes.h"
#include "sim/motion/motion_source.h"

namespace irbench {
namespace {

KeyframeMotion Ramp(const std::string& name, double x0, double x1, double seconds) {
  Keyframe a, b;
  a.t = 0;
  a.pose.root_offset = {x0, 0, 0};
  b.t = seconds;
  b.pose.root_offset = {x1, 0, 0};
  return KeyframeMotion(name, {a, b});
}

TEST(KeyframesTest, InterpolatesAndHolds) {
  Keyframe a, b;
  a.t = 0;
  b.t = 2;
  b.pose.root_offset = {1, 0, 0};
  b.pose.local_rotation[kRightElbow] = RotationZXYDeg({0, 0, 90});
  const KeyframeMotion motion("test", {a, b});
  EXPECT_NEAR(motion.At(1.0).root_offset.x(), 0.5, 1e-12);  // smoothstep(0.5) = 0.5
  EXPECT_NEAR(motion.At(0.5).root_offset.x(), 0.15625, 1e-12);  // smoothstep(0.25)
  EXPECT_NEAR(Eigen::AngleAxisd(motion.At(1.0).local_rotation[kRightElbow]).angle(), M_PI / 4, 1e-9);
  EXPECT_NEAR(motion.At(5.0).root_offset.x(), 1.0, 1e-12);
  EXPECT_NEAR(motion.At(-1.0).root_offset.x(), 0.0, 1e-12);
}

TEST(KeyframesTest, ShippedMotionsLoad) {
  for (const char* name : {"wave", "stand", "point_keys", "enter_wave_leave"}) {
    const auto motion =
        LoadKeyframes(std::string(IRBENCH_SOURCE_DIR) + "/motions/" + name + ".json");
    EXPECT_GT(motion.Duration(), 1.0) << name;
  }
}

TEST(SequenceMotionTest, PlaysItemsInTurnAndCrossfades) {
  auto a = std::make_shared<KeyframeMotion>(Ramp("a", 0, 1, 2));
  auto b = std::make_shared<KeyframeMotion>(Ramp("b", 5, 6, 2));
  const SequenceMotion seq("ab", {{a, 0}, {b, 0.5}});
  EXPECT_DOUBLE_EQ(seq.Duration(), 3.5);
  EXPECT_DOUBLE_EQ(seq.StartOf(1), 1.5);
  EXPECT_NEAR(seq.At(1.0).root_offset.x(), a->At(1.0).root_offset.x(), 1e-12);
  // Halfway through the crossfade the weight is smoothstep(0.5) = 0.5.
  const double mid = 0.5 * (a->At(1.75).root_offset.x() + b->At(0.25).root_offset.x());
  EXPECT_NEAR(seq.At(1.75).root_offset.x(), mid, 1e-12);
  EXPECT_NEAR(seq.At(3.0).root_offset.x(), b->At(1.5).root_offset.x(), 1e-12);
}

TEST(SequenceMotionTest, EventsAreShifted) {
  Keyframe k0, k1;
  k1.t = 2;
  auto a = std::make_shared<KeyframeMotion>("a", std::vector<Keyframe>{k0, k1},
                                            std::vector<MotionEvent>{{"gesture", "g", "", 0.5, 1.5}});
  const SequenceMotion seq("aa", {{a, 0}, {a, 0.5}});
  const auto events = seq.Events();
  ASSERT_EQ(events.size(), 2u);
  EXPECT_DOUBLE_EQ(events[1].start, 2.0);
  EXPECT_DOUBLE_EQ(events[1].end, 3.0);
  EXPECT_DOUBLE_EQ(LoopMotion(a, 3, 0.5)->Duration(), 5.0);
}

TEST(MirrorMotionTest, ForwardKinematicsIsMirrored) {
  const Avatar avatar = BuildTubeAvatar(AvatarParams{});
  Pose pose;
  pose.root_offset = {0.3, 0.1, -0.05};
  for (int j = 0; j < kJointCount; ++j) pose.local_rotation[j] = RotationZXYDeg({5.0 * j, 11.0 - j, 3.0 * j});
  const JointTransforms fk = ForwardKinematics(avatar.skeleton, pose);
  const JointTransforms fm = ForwardKinematics(avatar.skeleton, MirrorPose(pose));
  const std::pair<int, int> pairs[] = {{kRightWrist, kLeftWrist}, {kRightElbow, kLeftElbow},
                                       {kRightAnkle, kLeftAnkle}, {kHead, kHead}, {kChest, kChest}};
  for (const auto& [r, l] : pairs) {
    Eigen::Vector3d p = fk[r].translation();
    p.x() = -p.x();
    EXPECT_NEAR((fm[l].translation() - p).norm(), 0.0, 1e-12) << JointName(r);
  }
}

TEST(TimeWarpMotionTest, SpeedAndPiecewise) {
  auto a = std::make_shared<KeyframeMotion>(Ramp("a", 0, 1, 2));
  const MotionPtr fast = TimeWarpMotion::Speed(a, 2.0);
  EXPECT_DOUBLE_EQ(fast->Duration(), 1.0);
  EXPECT_NEAR(fast->At(0.5).root_offset.x(), a->At(1.0).root_offset.x(), 1e-12);
  const TimeWarpMotion warp(a, {{0, 0}, {1, 0.5}, {2, 2}});
  EXPECT_DOUBLE_EQ(warp.SourceTime(0.5), 0.25);
  EXPECT_DOUBLE_EQ(warp.SourceTime(1.5), 1.25);
  EXPECT_DOUBLE_EQ(warp.OutputTime(1.25), 1.5);
}

TEST(LayerMotionTest, TakesListedJointsFromOverlay) {
  Keyframe k;
  k.pose.local_rotation[kRightElbow] = RotationZXYDeg({0, 0, 90});
  k.pose.local_rotation[kLeftElbow] = RotationZXYDeg({0, 0, -90});
  Keyframe k1 = k;
  k1.t = 1;
  auto over = std::make_shared<KeyframeMotion>("o", std::vector<Keyframe>{k, k1});
  auto base = std::make_shared<KeyframeMotion>(Ramp("b", 0, 1, 1));
  const LayerMotion layer(base, over, ArmJoints(+1));
  const Pose p = layer.At(0.5);
  EXPECT_NEAR(p.local_rotation[kRightElbow].angularDistance(k.pose.local_rotation[kRightElbow]), 0, 1e-12);
  EXPECT_NEAR(p.local_rotation[kLeftElbow].angularDistance(Eigen::Quaterniond::Identity()), 0, 1e-12);
  EXPECT_NEAR(p.root_offset.x(), 0.5, 1e-12);
}

}  // namespace
}  // namespace irbench
