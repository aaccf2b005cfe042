#pragma once
// The motion-label features of one arm per frame (thesis 7.1.3), from the
// tracker's own joints (a track.jsonl line), never the truth:
//   - positions: the elbow and the wrist relative to the shoulder in the
//     upper-body frame (x towards the right shoulder, y forward, z from the
//     waist to the neck), divided by the body height; Euclidean (x, y, z) and
//     cylindrical about the vertical through the shoulder (rho, theta with
//     theta = atan2(x, y), 0 straight ahead);
//   - velocities of the elbow and the wrist relative to the shoulder, m/s,
//     over the last kVelocityFrames frames, as the truth's labels take them
//     (sim/motion/labels.h): the change of the world shoulder-to-joint
//     vector turned into the current upper-body frame, so the frame's own
//     jitter is no motion; the unit direction (Euclidean and cylindrical:
//     d rho, rho d theta, dz) and the speed; the direction fades to 0 below
//     kDirectionSpeed so that jitter at a pause gives no direction;
//   - the same over the last kLongVelocityFrames frames for the wrist
//     (direction and speed) and the elbow (speed): the tracked joints jitter
//     by a centimetre or two, which over 3 frames alone is a speed of
//     0.1-0.3 m/s, as much as the PAUSE threshold (0.12 m/s) of the labels;
//   - the rest-state SVM's margin (thesis 6.4), positive at rest.
// The left arm is mirrored onto the right (x negated), so one model serves
// both arms; its labels are mirrored with it (MirrorMotionLabel).

#include <Eigen/Core>
#include <array>
#include <deque>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

namespace irbench {

class RestClassifier;

constexpr int kMotionFeatureCount = 30;
constexpr int kVelocityFrames = 3;
constexpr int kLongVelocityFrames = 9;
constexpr double kDirectionSpeed = 0.05;  // m/s
using MotionFeatures = Eigen::Matrix<double, kMotionFeatureCount, 1>;

// The features' names, in order.
const std::vector<std::string>& MotionFeatureNames();

// What the features need of one tracked frame (world metres, seconds).
struct MotionObservation {
  double t = 0;
  double height_m = 0;
  Eigen::Vector3d waist, neck;
  std::array<Eigen::Vector3d, 2> shoulder, elbow, wrist;  // right, left
  std::array<double, 2> rest_margin{0, 0};                // right, left
};

// From a track.jsonl line: nullopt unless the state is "tracking" with the
// joints and height the features need. `rest` may be null (margin 0).
std::optional<MotionObservation> MotionObservationFromTrackLine(const nlohmann::json& line, const RestClassifier* rest);

// LEFT <-> RIGHT; every other label as it is.
std::string MirrorMotionLabel(const std::string& label);

// Frame by frame: the features of both arms (right, left-mirrored), or
// nullopt for a frame without an observation, which also restarts the
// velocity history.
class MotionFeatureExtractor {
 public:
  std::optional<std::array<MotionFeatures, 2>> Update(const std::optional<MotionObservation>& observation);

 private:
  struct ArmSample {
    double t;
    Eigen::Vector3d elbow, wrist;  // shoulder-relative, world frame, metres
  };
  std::array<std::deque<ArmSample>, 2> history_;
};

}  // namespace irbench
