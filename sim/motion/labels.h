#pragma once
// Truth labels computed from the exact motion (rules in docs/truth.md):
// gesture (from the motion's events), posture atoms, rest state per arm,
// motion label per arm (thesis 7.1) and pointing (thesis 6.5).

#include <Eigen/Core>
#include <nlohmann/json.hpp>
#include <string>

#include "sim/body/avatar.h"
#include "sim/motion/motion_source.h"
#include "sim/scene/scene.h"

namespace irbench {

// The nine motion labels of thesis 7.1.
const std::vector<std::string>& MotionLabelNames();

// Rest rule: in the upper-body (chest) frame, the upper arm within 30° of
// straight down and the forearm within 45° of straight down.
bool ArmAtRest(const Eigen::Vector3d& upper_arm_dir, const Eigen::Vector3d& forearm_dir);

// Motion-label rule on the wrist's velocity relative to the shoulder, in the
// chest frame (x the person's right, y forward, z up), m/s: REST if the arm is
// at rest; PAUSE below 0.12 m/s; else the axis holding at least 80% of the
// speed gives LEFT/RIGHT (-x/+x), BACKWARD/FORWARD (-y/+y), DOWN/UP (-z/+z);
// otherwise OTHER.
std::string MotionLabel(bool rest, const Eigen::Vector3d& velocity);
constexpr double kPauseSpeed = 0.12;
constexpr double kAxisShare = 0.8;

// Atom of one arm: A0 at rest; else by the elevation of the hand tip seen from
// the shoulder in the chest frame: A2 >= 62.5°, A3 >= 22.5°, A1 >= -22.5°, A4 below.
std::string ArmAtom(bool rest, const Eigen::Vector3d& shoulder_to_tip);

class Labeler {
 public:
  // `scene` may be null (no pointing then).
  Labeler(const Avatar& avatar, const Scene* scene, const MotionSource& motion);
  // {"gesture", "posture", "rest", "motion"} at time t.
  nlohmann::json Labels(double t) const;
  // {"left", "right"} pointing rays, or nulls.
  nlohmann::json Pointing(double t) const;

 private:
  struct Arm {
    Eigen::Vector3d shoulder, elbow, wrist, tip;
  };
  struct State {
    Eigen::Matrix3d chest;
    Eigen::Vector3d head;
    Arm arm[2];  // right, left
  };
  State StateAt(double t) const;

  const Avatar& avatar_;
  const Scene* scene_;
  const MotionSource& motion_;
  std::vector<MotionEvent> events_;
};

}  // namespace irbench
