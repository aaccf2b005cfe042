#include "sim/motion/keyframes.h"

#include <algorithm>
#include <cmath>

#include "common/json_reader.h"

namespace irbench {

KeyframeMotion::KeyframeMotion(std::string name, std::vector<Keyframe> keys,
                               std::vector<MotionEvent> events)
    : MotionSource(std::move(name)), keys_(std::move(keys)), events_(std::move(events)) {
  if (keys_.empty()) throw std::invalid_argument("KeyframeMotion needs at least one key");
}

Pose KeyframeMotion::At(double t) const {
  if (t <= keys_.front().t) return keys_.front().pose;
  if (t >= keys_.back().t) return keys_.back().pose;
  const auto next = std::upper_bound(keys_.begin(), keys_.end(), t,
                                     [](double time, const Keyframe& k) { return time < k.t; });
  const Keyframe& b = *next;
  const Keyframe& a = *(next - 1);
  double u = (t - a.t) / (b.t - a.t);
  u = u * u * (3 - 2 * u);  // ease in and out: zero velocity at keys
  Pose pose;
  pose.root_offset = a.pose.root_offset + (b.pose.root_offset - a.pose.root_offset) * u;
  for (int j = 0; j < kJointCount; ++j) {
    pose.local_rotation[j] = a.pose.local_rotation[j].slerp(u, b.pose.local_rotation[j]);
  }
  return pose;
}

KeyframeMotion LoadKeyframes(const std::filesystem::path& path) {
  const JsonNode root = ParseJsonFile(path.string());
  root.CheckKeys({"format", "name", "description", "keys"});
  if (root.GetString("format") != "irbench.keyframes/1") {
    root["format"].Fail("expected \"irbench.keyframes/1\"");
  }
  const JsonNode keys = root["keys"];
  if (keys.Size() == 0) keys.Fail("needs at least one key");
  std::vector<Keyframe> frames;
  for (size_t i = 0; i < keys.Size(); ++i) {
    const JsonNode k = keys[i];
    k.CheckKeys({"t", "root", "heading_deg", "joints"});
    Keyframe key;
    key.t = k.GetDouble("t");
    if (key.t < 0) k["t"].Fail("must be non-negative");
    if (!frames.empty() && key.t <= frames.back().t) k["t"].Fail("keys must be in increasing time");
    if (k.Has("root")) key.pose.root_offset = k.GetVec3("root");
    const double heading = k.GetDouble("heading_deg", 0.0);
    if (k.Has("joints")) {
      const JsonNode joints = k["joints"];
      for (const std::string& name : joints.Keys()) {
        const auto joint = JointFromName(name);
        if (!joint) joints[name].Fail("unknown joint (see docs/formats.md for the names)");
        key.pose.local_rotation[*joint] = RotationZXYDeg(joints[name].Vec3());
      }
    }
    key.pose.local_rotation[kPelvis] =
        Eigen::Quaterniond(Eigen::AngleAxisd(heading * M_PI / 180.0, Eigen::Vector3d::UnitZ())) *
        key.pose.local_rotation[kPelvis];
    frames.push_back(key);
  }
  return KeyframeMotion(root.GetString("name", path.stem().string()), std::move(frames));
}

}  // namespace irbench
