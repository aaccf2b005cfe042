#include "sim/motion/labels.h"

#include "sequence_format/posture_labels.h"

#include <cmath>

namespace irbench {
namespace {

constexpr double kRadiansPerDegree = M_PI / 180.0;
constexpr double kVelocityStep = 0.05;  // s, central difference half-step
constexpr double kStraightElbowDeg = 25;

double AngleDeg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::acos(std::clamp(a.normalized().dot(b.normalized()), -1.0, 1.0)) / kRadiansPerDegree;
}

nlohmann::json Vec(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

}  // namespace

const std::vector<std::string>& MotionLabelNames() {
  static const std::vector<std::string> names = {"REST", "PAUSE", "LEFT",    "RIGHT", "UP",
                                                 "DOWN", "FORWARD", "BACKWARD", "OTHER"};
  return names;
}

bool ArmAtRest(const Eigen::Vector3d& upper_arm_dir, const Eigen::Vector3d& forearm_dir) {
  const Eigen::Vector3d down(0, 0, -1);
  return AngleDeg(upper_arm_dir, down) <= 30.0 && AngleDeg(forearm_dir, down) <= 45.0;
}

std::string MotionLabel(bool rest, const Eigen::Vector3d& v) {
  if (rest) return "REST";
  const double speed = v.norm();
  if (speed < kPauseSpeed) return "PAUSE";
  int axis;
  const double share = v.cwiseAbs().maxCoeff(&axis) / speed;
  if (share < kAxisShare) return "OTHER";
  static const char* kNames[3][2] = {{"LEFT", "RIGHT"}, {"BACKWARD", "FORWARD"}, {"DOWN", "UP"}};
  return kNames[axis][v[axis] > 0 ? 1 : 0];
}

std::string ArmAtom(bool rest, const Eigen::Vector3d& shoulder_to_tip) {
  if (rest) return std::string(kRestAtom);
  const double el = std::asin(std::clamp(shoulder_to_tip.normalized().z(), -1.0, 1.0)) / kRadiansPerDegree;
  for (const ArmAtomBand& band : kArmAtomBands) {
    if (el >= band.min_deg) return std::string(band.name);
  }
  return std::string(kArmAtomBands.back().name);
}

Labeler::Labeler(const Avatar& avatar, const Scene* scene, const MotionSource& motion)
    : avatar_(avatar), scene_(scene), motion_(motion), events_(motion.Events()) {}

Labeler::State Labeler::StateAt(double t) const {
  const JointTransforms fk = ForwardKinematics(avatar_.skeleton, motion_.At(t));
  State s;
  s.chest = fk[kChest].linear();
  for (const BoneMarker& m : avatar_.markers) {
    const Eigen::Vector3d p = fk[m.joint] * m.offset_in_joint;
    if (m.name == "head") s.head = p;
    if (m.name == "right_hand_tip") s.arm[0].tip = p;
    if (m.name == "left_hand_tip") s.arm[1].tip = p;
  }
  for (int k = 0; k < 2; ++k) {
    const int sh = k == 0 ? kRightShoulder : kLeftShoulder;
    s.arm[k].shoulder = fk[sh].translation();
    s.arm[k].elbow = fk[sh + 1].translation();
    s.arm[k].wrist = fk[sh + 2].translation();
  }
  return s;
}

nlohmann::json Labeler::Labels(double t) const {
  const State now = StateAt(t);
  const State before = StateAt(t - kVelocityStep);
  const State after = StateAt(t + kVelocityStep);
  nlohmann::json rest = nlohmann::json::object(), motion = nlohmann::json::object();
  std::string atom[2];
  double lift[2];
  for (int k = 0; k < 2; ++k) {
    const Arm& a = now.arm[k];
    const Eigen::Matrix3d to_chest = now.chest.transpose();
    const Eigen::Vector3d upper = to_chest * (a.elbow - a.shoulder);
    const Eigen::Vector3d fore = to_chest * (a.wrist - a.elbow);
    const bool at_rest = ArmAtRest(upper, fore);
    const Eigen::Vector3d rel_after = after.arm[k].wrist - after.arm[k].shoulder;
    const Eigen::Vector3d rel_before = before.arm[k].wrist - before.arm[k].shoulder;
    const Eigen::Vector3d v = to_chest * (rel_after - rel_before) / (2 * kVelocityStep);
    const char* side = k == 0 ? "right" : "left";
    rest[side] = at_rest;
    motion[side] = MotionLabel(at_rest, v);
    atom[k] = ArmAtom(at_rest, to_chest * (a.tip - a.shoulder));
    lift[k] = AngleDeg(upper, Eigen::Vector3d(0, 0, -1));
  }
  // Primary: the arm farther from hanging down.
  const int primary = (atom[0] != "A0" && (atom[1] == "A0" || lift[0] >= lift[1])) ? 0 : 1;
  nlohmann::json gesture = nullptr;
  for (const MotionEvent& e : events_) {
    if (e.kind == "gesture" && t >= e.start && t <= e.end) gesture = e.value;
  }
  return {{"gesture", gesture},
          {"posture", {atom[primary], atom[1 - primary]}},
          {"rest", rest},
          {"motion", motion}};
}

nlohmann::json Labeler::Pointing(double t) const {
  nlohmann::json out = {{"left", nullptr}, {"right", nullptr}};
  if (!scene_) return out;
  const State s = StateAt(t);
  for (int k = 0; k < 2; ++k) {
    const Arm& a = s.arm[k];
    const Eigen::Matrix3d to_chest = s.chest.transpose();
    const Eigen::Vector3d upper = a.elbow - a.shoulder, fore = a.wrist - a.elbow;
    if (ArmAtRest(to_chest * upper, to_chest * fore) || AngleDeg(upper, fore) > kStraightElbowDeg) continue;
    const Eigen::Vector3d dir = (a.tip - s.head).normalized();
    // The nearest screen hit along the ray.
    double best = std::numeric_limits<double>::infinity();
    nlohmann::json hit = nullptr;
    for (const ScreenSurface& screen : scene_->screens) {
      const auto st = screen.Intersect(s.head, dir);
      if (!st) continue;
      const double dist = (screen.PointAt(*st) - s.head).norm();
      if (dist >= best) continue;
      best = dist;
      const std::string target = screen.NearestTarget(*st);
      hit = {{"origin", Vec(s.head)},
             {"dir", Vec(dir)},
             {"screen", screen.name},
             {"screen_hit", {st->x(), st->y()}},
             {"target", target.empty() ? nlohmann::json(nullptr) : nlohmann::json(target)}};
    }
    if (hit.is_null()) continue;
    const char* side = k == 0 ? "right" : "left";
    hit["aimed_at"] = nullptr;
    for (const MotionEvent& e : events_) {
      if (e.kind == "point" && e.side == side && t >= e.start && t <= e.end) hit["aimed_at"] = e.value;
    }
    out[side] = hit;
  }
  return out;
}

}  // namespace irbench
