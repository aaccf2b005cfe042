#include "ci/sweep/sweep_pose.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "common/atomic_file.h"
#include "sim/body/skeleton.h"
#include "sim/motion/library.h"

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

// One component: a number (returned) or a range (added to `pose.dims` and
// its `from` returned), within lo..hi.
double ReadComponent(const JsonNode& v, PoseDim dim, double lo, double hi, const std::string& unit, bool grid,
                     PoseAxis* pose) {
  const auto text = [](double x) {
    std::ostringstream out;
    out << x;
    return out.str();
  };
  const std::string within = "must be within " + text(lo) + ".." + text(hi) + unit;
  if (v.raw().is_number()) {
    const double fixed = v.Number();
    if (!(fixed >= lo && fixed <= hi)) v.Fail(within);
    return fixed;
  }
  v.CheckKeys({"from", "to", "steps"});
  dim.range.from = v.GetDouble("from");
  dim.range.to = v.GetDouble("to");
  dim.range.steps = v.Has("steps") ? v.GetInt("steps") : 1;
  if (dim.range.steps < 1 || dim.range.steps > 1000) v["steps"].Fail("must be in 1..1000");
  if (!(dim.range.from >= lo && dim.range.from <= hi) || !(dim.range.to >= lo && dim.range.to <= hi)) {
    v.Fail("from and to " + within);
  }
  if (dim.range.steps > 1 && dim.range.from == dim.range.to) v.Fail("an empty range: from equals to with several steps");
  if (grid && dim.range.steps == 1 && dim.range.from != dim.range.to) v.Fail("from and to differ: give steps (a grid)");
  pose->dims.push_back(dim);
  return dim.range.from;
}

}  // namespace

PoseAxis ReadPoseAxis(const JsonNode& a, bool grid) {
  a.CheckKeys({"pose", "joints", "atoms", "move_s", "hold_s"});
  PoseAxis pose;
  pose.move_s = a.GetDouble("move_s", 1.0);
  pose.hold_s = a.GetDouble("hold_s", 2.0);
  if (!(pose.move_s >= 0.1 && pose.move_s <= 60)) a["move_s"].Fail("must be in 0.1..60 s");
  if (!(pose.hold_s >= 0.1 && pose.hold_s <= 600)) a["hold_s"].Fail("must be in 0.1..600 s");
  if (a.Has("joints") == a.Has("atoms")) a.Fail("give either `joints` (rotations) or `atoms` (the atoms' weights)");
  pose.atoms = a.Has("atoms");
  if (pose.atoms && pose.hold_s > 60) a["hold_s"].Fail("must be in 0.1..60 s for atoms (the library's `posture`)");
  if (pose.atoms) {
    const JsonNode arms = a["atoms"];
    if (arms.Keys().empty()) arms.Fail("no arms");
    for (const std::string& arm : arms.Keys()) {
      const JsonNode w = arms[arm];
      if (arm != "right" && arm != "left") w.Fail("an arm is `right` or `left`");
      if (w.Keys().empty()) w.Fail("no atoms");
      std::array<double, 5> weights{};
      for (const std::string& name : w.Keys()) {
        const int atom = PostureAtomIndex(name);
        if (atom < 0) w[name].Fail(std::string("unknown atom (") + kPostureAtomNames + ")");
        PoseDim dim{arm, atom, {}, true};
        weights[dim.component] = ReadComponent(w[name], dim, 0, 1, "", grid, &pose);
      }
      pose.weights[arm] = weights;
    }
  } else {
    const JsonNode joints = a["joints"];
    if (joints.Keys().empty()) joints.Fail("no joints");
    for (const std::string& name : joints.Keys()) {
      const JsonNode j = joints[name];
      if (!JointFromName(name)) j.Fail("unknown joint (see docs/formats.md for the names)");
      if (j.Size() != 3) j.Fail("expected [x, y, z]: three numbers or ranges");
      Eigen::Vector3d fixed;
      for (int c = 0; c < 3; ++c) {
        fixed[c] = ReadComponent(j[size_t(c)], PoseDim{name, c, {}, false}, -kMaxDeg, kMaxDeg, " degrees", grid, &pose);
      }
      pose.fixed[name] = fixed;
    }
  }
  if (pose.dims.empty()) {
    a[pose.atoms ? "atoms" : "joints"].Fail("no ranges: a pose axis needs at least one component that varies");
  }
  return pose;
}

void WritePoseMotion(const PoseAxis& pose, const std::vector<double>& values, const std::string& name,
                     const std::string& description, const std::filesystem::path& file) {
  std::filesystem::create_directories(file.parent_path());
  if (pose.atoms) {
    // A session of the library's `posture` motion, so that the rest posture
    // and the tempo are the person's own.
    std::map<std::string, std::array<double, 5>> weights = pose.weights;
    // A grid's last step may land a rounding step beyond its `to`.
    for (size_t d = 0; d < pose.dims.size(); ++d) {
      weights[pose.dims[d].joint][pose.dims[d].component] = std::clamp(values[d], 0.0, 1.0);
    }
    nlohmann::json item = {{"motion", "posture"}, {"move_s", pose.move_s}, {"hold_s", pose.hold_s}};
    for (const auto& [arm, w] : weights) {
      item[arm] = nlohmann::json::object();
      for (int atom = 0; atom < 5; ++atom) {
        if (w[atom] > 0) item[arm]["A" + std::to_string(atom)] = w[atom];
      }
      if (item[arm].empty()) item[arm] = "A0";
    }
    const nlohmann::json session = {
        {"format", "irbench.session/1"}, {"name", name}, {"description", description}, {"items", {item}}};
    AtomicWriteFile(file, session.dump(1) + "\n");
    return;
  }
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
  AtomicWriteFile(file, motion.dump(1) + "\n");
}

}  // namespace irbench
