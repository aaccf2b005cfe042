#include "tracker/motion_labels/motion_features.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>

namespace irbench {
namespace {

// A 1.8 m person facing `yaw` (0: +y) whose right wrist sits `wrist_in_body`
// from the right shoulder (body frame: x right, y forward, z up) and whose
// left wrist mirrors it.
MotionObservation Person(double t, double yaw, const Eigen::Vector3d& wrist_in_body) {
  const Eigen::Matrix3d world_from_body = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Eigen::Vector3d origin(1.0, -2.0, 0.0);
  auto world = [&](const Eigen::Vector3d& p) { return Eigen::Vector3d(origin + world_from_body * p); };
  MotionObservation o;
  o.t = t;
  o.height_m = 1.8;
  o.waist = world({0, 0, 1.0});
  o.neck = world({0, 0, 1.45});
  const Eigen::Vector3d mirror(-1, 1, 1);
  for (int a = 0; a < 2; ++a) {
    const Eigen::Vector3d s(a == 0 ? 0.2 : -0.2, 0, 1.4);
    const Eigen::Vector3d e(0, 0, -0.3), w = wrist_in_body;
    o.shoulder[a] = world(s);
    o.elbow[a] = world(s + (a == 0 ? e : Eigen::Vector3d(e.cwiseProduct(mirror))));
    o.wrist[a] = world(s + (a == 0 ? w : Eigen::Vector3d(w.cwiseProduct(mirror))));
    o.rest_margin[a] = a == 0 ? 0.7 : -0.4;
  }
  return o;
}

// The wrist moving at 0.5 m/s towards the person's right (the left wrist
// mirrored: towards the person's left), whatever way the person faces.
TEST(MotionFeaturesTest, PositionsAndVelocitiesInTheShoulderFrame) {
  for (double yaw : {0.0, 1.2, -2.5}) {
    MotionFeatureExtractor extractor;
    std::optional<std::array<MotionFeatures, 2>> f;
    for (int i = 0; i <= kVelocityFrames; ++i) {
      const double t = i / 30.0;
      f = extractor.Update(Person(t, yaw, Eigen::Vector3d(0.1 + 0.5 * t, 0.3, -0.2)));
      ASSERT_TRUE(f);
    }
    const double x = 0.1 + 0.5 * kVelocityFrames / 30.0;
    for (int a = 0; a < 2; ++a) {
      const MotionFeatures& g = (*f)[a];  // the left arm mirrored: the same features
      EXPECT_NEAR(g(5), x / 1.8, 1e-9);                             // wrist_x
      EXPECT_NEAR(g(6), 0.3 / 1.8, 1e-9);                           // wrist_y
      EXPECT_NEAR(g(7), -0.2 / 1.8, 1e-9);                          // wrist_z
      EXPECT_NEAR(g(8), std::hypot(x, 0.3) / 1.8, 1e-9);            // wrist_rho
      EXPECT_NEAR(g(9), std::atan2(x, 0.3), 1e-9);                  // wrist_theta
      EXPECT_NEAR(g(2), -0.3 / 1.8, 1e-9);                          // elbow_z
      EXPECT_NEAR(g(17), 1.0, 1e-9);                                // wrist_dir_x
      EXPECT_NEAR(g(18), 0.0, 1e-9);
      EXPECT_NEAR(g(19), 0.0, 1e-9);
      const double rho = std::hypot(x, 0.3);
      EXPECT_NEAR(g(20), x / rho, 1e-9);    // d rho: the radial share of the move
      EXPECT_NEAR(g(21), 0.3 / rho, 1e-9);  // rho d theta: the tangential share
      EXPECT_NEAR(g(23), 0.5, 1e-9);        // wrist speed
      EXPECT_NEAR(g(16), 0.0, 1e-9);        // the elbow does not move
      EXPECT_NEAR(g(10), 0.0, 1e-9);        // ... so it has no direction
    }
    EXPECT_DOUBLE_EQ((*f)[0](29), 0.7);
    EXPECT_DOUBLE_EQ((*f)[1](29), -0.4);
    // The long baseline has only kVelocityFrames frames of history here:
    // the same constant velocity.
    EXPECT_NEAR((*f)[0](24), 1.0, 1e-9);
    EXPECT_NEAR((*f)[0](27), 0.5, 1e-9);
    EXPECT_NEAR((*f)[0](28), 0.0, 1e-9);
  }
  EXPECT_EQ(MotionFeatureNames().size(), static_cast<size_t>(kMotionFeatureCount));
  EXPECT_EQ(MotionFeatureNames()[23], "wrist_speed");
}

// A person turning at 1 rad/s, the arm still in the body: the shoulder-to-
// wrist vector turns with the body, so the wrist moves (the truth's rule
// takes the world vector's change), by the chord 2 r sin(dtheta / 2).
TEST(MotionFeaturesTest, TurningWithTheBodyIsMotionOfTheWorldVector) {
  MotionFeatureExtractor extractor;
  std::optional<std::array<MotionFeatures, 2>> f;
  for (int i = 0; i <= kVelocityFrames; ++i) f = extractor.Update(Person(i / 30.0, 1.0 * i / 30.0, {0.1, 0.3, -0.2}));
  const double dt = kVelocityFrames / 30.0, r = std::hypot(0.1, 0.3);
  EXPECT_NEAR((*f)[0](23), 2 * r * std::sin(1.0 * dt / 2) / dt, 1e-9);
  EXPECT_NEAR((*f)[0](19), 0.0, 1e-9);  // no vertical part
  // Turning left (counter-clockwise from above) moves a wrist in front of
  // the right shoulder to the person's left: negative x, for both arms
  // (the left arm mirrored: towards its outside).
  EXPECT_LT((*f)[0](17), -0.5);
  EXPECT_GT((*f)[1](17), 0.5);
}

// Slow moves give a speed but no direction; a gap restarts the history.
TEST(MotionFeaturesTest, SlowMovesHaveNoDirectionAndGapsRestart) {
  MotionFeatureExtractor extractor;
  std::optional<std::array<MotionFeatures, 2>> f;
  for (int i = 0; i <= kVelocityFrames; ++i) f = extractor.Update(Person(i / 30.0, 0, {0.1, 0.3, 0.01 * i / 30.0}));
  EXPECT_NEAR((*f)[0](23), 0.01, 1e-9);
  EXPECT_NEAR((*f)[0](19), 0.01 / kDirectionSpeed, 1e-9);
  EXPECT_FALSE(extractor.Update(std::nullopt));
  f = extractor.Update(Person(1.0, 0, {0.5, 0.3, 0}));
  EXPECT_EQ((*f)[0](23), 0.0);  // no history after the gap
}

// A wrist jittering by +-1 cm each frame: 2 cm over 3 frames (0.2 m/s),
// the same 2 cm over 9 (0.067 m/s): the long baseline sees a pause.
TEST(MotionFeaturesTest, TheLongBaselineDampsJitter) {
  MotionFeatureExtractor extractor;
  std::optional<std::array<MotionFeatures, 2>> f;
  for (int i = 0; i <= kLongVelocityFrames; ++i) {
    f = extractor.Update(Person(i / 30.0, 0, {0.1 + (i % 2 ? 0.01 : -0.01), 0.3, -0.2}));
  }
  EXPECT_NEAR((*f)[0](23), 0.02 / (kVelocityFrames / 30.0), 1e-9);
  EXPECT_NEAR((*f)[0](27), 0.02 / (kLongVelocityFrames / 30.0), 1e-9);
}

TEST(MotionFeaturesTest, ObservationFromTrackLine) {
  nlohmann::json line = {{"state", "tracking"}, {"t", 0.5}, {"height_m", 1.7}};
  nlohmann::json joints;
  joints["waist"] = {0, 0, 1.0};
  joints["neck"] = {0, 0, 1.4};
  joints["right_shoulder"] = {0.2, 0, 1.4};
  joints["left_shoulder"] = {-0.2, 0, 1.4};
  joints["right_elbow"] = {0.2, 0, 1.1};
  joints["left_elbow"] = {-0.2, 0, 1.1};
  joints["right_wrist"] = {0.2, 0.1, 0.85};
  joints["left_wrist"] = {-0.2, 0, 0.85};
  line["joints3d"] = joints;
  const auto o = MotionObservationFromTrackLine(line, nullptr);
  ASSERT_TRUE(o);
  EXPECT_EQ(o->t, 0.5);
  EXPECT_EQ(o->wrist[0], Eigen::Vector3d(0.2, 0.1, 0.85));
  EXPECT_EQ(o->rest_margin[0], 0.0);
  line["state"] = "partial";
  EXPECT_FALSE(MotionObservationFromTrackLine(line, nullptr));
  line["state"] = "tracking";
  line["joints3d"]["left_wrist"] = nullptr;
  EXPECT_FALSE(MotionObservationFromTrackLine(line, nullptr));
  EXPECT_EQ(MirrorMotionLabel("LEFT"), "RIGHT");
  EXPECT_EQ(MirrorMotionLabel("RIGHT"), "LEFT");
  EXPECT_EQ(MirrorMotionLabel("UP"), "UP");
}

}  // namespace
}  // namespace irbench
