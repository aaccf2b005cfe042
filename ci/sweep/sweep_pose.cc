#include "ci/sweep/sweep_pose.h"

#include <cmath>

#include "common/atomic_file.h"
#include "sim/body/skeleton.h"

namespace irbench {
namespace {

constexpr double kMaxDeg = 360;

// The keyframe convention's standing pose (motions/stand.json): arms down.
std::map<std::string, Eigen::Vector3d> Standing() {
  return {{"right_shoulder", {0, 80, 0}}, {"left_shoulder", {0, -80, 0}},
          {"right_elbow", {0, 0, 10}},    {"left_elbow", {0, 0, -10}}};
}

nlohmann::json Key(double t, const std::map<std::string, Eigen::Vector3d>& joints) {
  nlohmann::json out = {{"t", t}, {"root", {0, 0, 0}}, {"joints", nlohmann::json::object()}};
  for (const auto& [name, r] : joints) out["joints"][name] = {r.x(), r.y(), r.z()};
  return out;
}

}  // namespace

PoseAxis ReadPoseAxis(const JsonNode& a, bool grid) {
  a.CheckKeys({"pose", "joints", "move_s", "hold_s"});
  PoseAxis pose;
  pose.move_s = a.GetDouble("move_s", 1.0);
  pose.hold_s = a.GetDouble("hold_s", 2.0);
  if (!(pose.move_s >= 0.1 && pose.move_s <= 60)) a["move_s"].Fail("must be in 0.1..60 s");
  if (!(pose.hold_s >= 0.1 && pose.hold_s <= 600)) a["hold_s"].Fail("must be in 0.1..600 s");
  const JsonNode joints = a["joints"];
  if (joints.Keys().empty()) joints.Fail("no joints");
  for (const std::string& name : joints.Keys()) {
    const JsonNode j = joints[name];
    if (!JointFromName(name)) j.Fail("unknown joint (see docs/formats.md for the names)");
    if (j.Size() != 3) j.Fail("expected [x, y, z]: three numbers or ranges");
    Eigen::Vector3d fixed;
    for (int c = 0; c < 3; ++c) {
      const JsonNode v = j[size_t(c)];
      if (v.raw().is_number()) {
        fixed[c] = v.Number();
        if (!(std::abs(fixed[c]) <= kMaxDeg)) v.Fail("must be within ±360 degrees");
        continue;
      }
      v.CheckKeys({"from", "to", "steps"});
      PoseDim dim;
      dim.joint = name;
      dim.component = c;
      dim.range.from = v.GetDouble("from");
      dim.range.to = v.GetDouble("to");
      dim.range.steps = v.Has("steps") ? v.GetInt("steps") : 1;
      if (dim.range.steps < 1 || dim.range.steps > 1000) v["steps"].Fail("must be in 1..1000");
      if (!(std::abs(dim.range.from) <= kMaxDeg) || !(std::abs(dim.range.to) <= kMaxDeg)) {
        v.Fail("from and to must be within ±360 degrees");
      }
      if (dim.range.steps > 1 && dim.range.from == dim.range.to) v.Fail("an empty range: from equals to with several steps");
      if (grid && dim.range.steps == 1 && dim.range.from != dim.range.to) v.Fail("from and to differ: give steps (a grid)");
      fixed[c] = dim.range.from;
      pose.dims.push_back(dim);
    }
    pose.fixed[name] = fixed;
  }
  if (pose.dims.empty()) joints.Fail("no ranges: a pose axis needs at least one component that varies");
  return pose;
}

void WritePoseMotion(const PoseAxis& pose, const std::vector<double>& values, const std::string& name,
                     const std::string& description, const std::filesystem::path& file) {
  const std::map<std::string, Eigen::Vector3d> standing = Standing();
  std::map<std::string, Eigen::Vector3d> held = standing;
  for (const auto& [joint, r] : pose.fixed) held[joint] = r;
  for (size_t d = 0; d < pose.dims.size(); ++d) held[pose.dims[d].joint][pose.dims[d].component] = values[d];
  // Standing lists every joint the pose moves, at its bind rotation where
  // standing does not set it (a key's unlisted joints are at bind).
  std::map<std::string, Eigen::Vector3d> start = standing;
  for (const auto& [joint, r] : held) start.try_emplace(joint, Eigen::Vector3d::Zero());
  const nlohmann::json motion = {{"format", "irbench.keyframes/1"},
                                 {"name", name},
                                 {"description", description},
                                 {"keys", {Key(0, start), Key(pose.move_s, held), Key(pose.move_s + pose.hold_s, held)}}};
  std::filesystem::create_directories(file.parent_path());
  AtomicWriteFile(file, motion.dump(1) + "\n");
}

}  // namespace irbench
