// Rig joints -> canonical joints by the shape of the hierarchy and the bind
// pose, for rigs whose joint names no table knows (see the header).

#include "sim/body/internal/joint_topology.h"

#include <Eigen/Core>
#include <algorithm>
#include <limits>
#include <map>
#include <set>
#include <vector>

#include "common/error.h"
#include "sim/body/skeleton.h"

namespace irbench::import_internal {
namespace {

using Eigen::Vector3d;

// The rig's weighted joints as a tree.
class WeightedTree {
 public:
  WeightedTree(const Rig& rig, const std::string& file) : rig_(rig), file_(file) {
    const int n = static_cast<int>(rig.joint_name.size());
    std::vector<double> own(n, 0.0);
    for (const auto& influences : rig.influence) {
      for (const auto& [joint, w] : influences) {
        if (joint >= 0 && joint < n && w > 0) own[joint] += w;
      }
    }
    // Weight and size below each joint: every joint adds itself to its
    // ancestors (the walk is bounded in case the parents form a loop).
    std::vector<double> below(n, 0.0);
    for (int j = 0; j < n; ++j) {
      for (int a = j, guard = 0; a >= 0 && a < n && guard <= n; a = rig.joint_parent[a], ++guard)
        below[a] += own[j];
    }
    live_.assign(n, false);
    for (int j = 0; j < n; ++j) live_[j] = below[j] > 0;
    size_.assign(n, 0);
    children_.assign(n, {});
    for (int j = 0; j < n; ++j) {
      if (!live_[j]) continue;
      for (int a = j, guard = 0; a >= 0 && a < n && guard <= n; a = rig.joint_parent[a], ++guard)
        ++size_[a];
      const int p = rig.joint_parent[j];
      if (p >= 0 && p < n) children_[p].push_back(j);
    }
  }

  const std::vector<int>& Children(int j) const { return children_[j]; }
  int Size(int j) const { return size_[j]; }
  const Vector3d& Position(int j) const { return rig_.joint_bind[j]; }
  std::string Name(int j) const { return "'" + rig_.joint_name[j] + "'"; }

  [[noreturn]] void Fail(const std::string& message) const {
    throw InputError(file_, "skin", message);
  }

  // The weighted root holding the most joints.
  int Root() const {
    int best = -1;
    for (size_t j = 0; j < live_.size(); ++j) {
      const int p = rig_.joint_parent[j];
      if (live_[j] && (p < 0 || p >= static_cast<int>(live_.size())) &&
          (best < 0 || size_[j] > size_[best]))
        best = static_cast<int>(j);
    }
    if (best < 0) Fail("no torso chain: no joint carries skin weight");
    return best;
  }

  // From `start`, down through joints with one weighted child; ends at the
  // first joint where chains branch, or at a leaf (both included).
  std::vector<int> Chain(int start) const {
    std::vector<int> chain = {start};
    for (size_t guard = 0; children_[chain.back()].size() == 1 && guard < live_.size(); ++guard)
      chain.push_back(children_[chain.back()][0]);
    return chain;
  }

  // Every weighted joint below `j`, itself included.
  std::vector<int> Below(int j) const {
    std::vector<int> out = {j};
    for (size_t i = 0; i < out.size() && out.size() <= live_.size(); ++i) {
      for (int c : children_[out[i]]) out.push_back(c);
    }
    return out;
  }

  // The children of `j` from the most joints below them to the fewest.
  std::vector<int> ChildrenBySize(int j) const {
    std::vector<int> kids = children_[j];
    std::stable_sort(kids.begin(), kids.end(), [&](int a, int b) { return size_[a] > size_[b]; });
    return kids;
  }

 private:
  const Rig& rig_;
  const std::string& file_;
  std::vector<bool> live_;
  std::vector<int> size_;
  std::vector<std::vector<int>> children_;
};

// Of `candidates`, the joint nearest the middle of `a` and `b`.
int NearestMiddle(const WeightedTree& tree, const std::vector<int>& candidates, int a, int b) {
  const Vector3d middle = 0.5 * (tree.Position(a) + tree.Position(b));
  int best = candidates.front();
  for (int c : candidates) {
    if ((tree.Position(c) - middle).norm() < (tree.Position(best) - middle).norm()) best = c;
  }
  return best;
}

struct Limb {
  int clavicle = -1, first = -1, middle = -1, last = -1;  // shoulder/hip, elbow/knee, wrist/ankle
};

Limb ArmFrom(const WeightedTree& tree, int start) {
  const std::vector<int> chain = tree.Chain(start);  // ends at the hand
  if (chain.size() < 3) {
    tree.Fail("no arm chain: the arm from " + tree.Name(start) + " has " + std::to_string(chain.size()) +
              " weighted joint(s); shoulder, elbow and wrist need three");
  }
  Limb arm;
  arm.last = chain.back();
  size_t first = 0;
  // A clavicle: a first bone shorter than 0.35 of the rest of the arm.
  if (chain.size() >= 4 && (tree.Position(chain[1]) - tree.Position(chain[0])).norm() <
                               0.35 * (tree.Position(chain.back()) - tree.Position(chain[1])).norm()) {
    arm.clavicle = chain[0];
    first = 1;
  }
  arm.first = chain[first];
  const std::vector<int> inner(chain.begin() + static_cast<long>(first) + 1, chain.end() - 1);
  arm.middle = NearestMiddle(tree, inner, arm.first, arm.last);
  return arm;
}

Limb LegFrom(const WeightedTree& tree, int start, const Vector3d& up) {
  // Down the leg through the child with the most joints (toes may branch).
  std::vector<int> chain = {start};
  for (int guard = 0; !tree.Children(chain.back()).empty() && guard < 1000; ++guard)
    chain.push_back(tree.ChildrenBySize(chain.back()).front());
  if (chain.size() < 3) {
    tree.Fail("no leg chain: the leg from " + tree.Name(start) + " has " + std::to_string(chain.size()) +
              " weighted joint(s); hip, knee and ankle need three");
  }
  // The ankle: the first joint from the third on whose bone onwards is level
  // (towards the toes) or shorter than half the bone before it (a foot), or
  // the chain's end.
  size_t ankle = chain.size() - 1;
  for (size_t i = 2; i + 1 < chain.size(); ++i) {
    const Vector3d bone = tree.Position(chain[i + 1]) - tree.Position(chain[i]);
    const double before = (tree.Position(chain[i]) - tree.Position(chain[i - 1])).norm();
    if (bone.norm() < 0.5 * before || (bone.norm() > 0 && std::abs(bone.normalized().dot(up)) < 0.7)) {
      ankle = i;
      break;
    }
  }
  Limb leg;
  leg.first = chain[0];
  leg.last = chain[ankle];
  leg.middle = NearestMiddle(tree, std::vector<int>(chain.begin() + 1, chain.begin() + static_cast<long>(ankle)),
                             leg.first, leg.last);
  return leg;
}

}  // namespace

JointMapping MapJointsByHierarchy(const Rig& rig, const std::string& file) {
  const WeightedTree tree(rig, file);

  // The pelvis: down from the root to the first branch of three or more.
  const std::vector<int> root_chain = tree.Chain(tree.Root());
  const int pelvis = root_chain.back();
  const std::vector<int> from_pelvis = tree.ChildrenBySize(pelvis);
  if (from_pelvis.size() < 3) {
    tree.Fail("no leg chain: the weighted hierarchy first branches at " + tree.Name(pelvis) + " into " +
              std::to_string(from_pelvis.size()) + " chain(s); a spine and two legs need three");
  }

  // The chest: up the spine to the first branch of three or more.
  const std::vector<int> spine_chain = tree.Chain(from_pelvis[0]);
  const int chest = spine_chain.back();
  const std::vector<int> from_chest = tree.ChildrenBySize(chest);
  if (from_chest.size() < 3) {
    std::string names;
    for (int c : from_chest) names += (names.empty() ? "" : ", ") + tree.Name(c);
    tree.Fail("no arm chain: the spine from " + tree.Name(from_pelvis[0]) + " branches at " + tree.Name(chest) +
              " into " + std::to_string(from_chest.size()) + " chain(s)" + (names.empty() ? "" : " (" + names + ")") +
              "; a neck and two arms need three");
  }
  Vector3d up = tree.Position(chest) - tree.Position(pelvis);
  if (!(up.norm() > 0)) tree.Fail("no torso chain: the pelvis " + tree.Name(pelvis) + " and chest coincide");
  up.normalize();

  // The neck and head reach highest above the chest; the arms are the two
  // largest of the others.
  auto height = [&](int c) {
    const std::vector<int> below = tree.Below(c);
    double sum = 0;
    for (int j : below) sum += (tree.Position(j) - tree.Position(chest)).dot(up);
    return sum / static_cast<double>(below.size());
  };
  int neck_start = from_chest[0];
  for (int c : from_chest) {
    if (height(c) > height(neck_start)) neck_start = c;
  }
  std::vector<int> arm_starts;
  for (int c : from_chest) {
    if (c != neck_start && arm_starts.size() < 2) arm_starts.push_back(c);
  }
  const std::vector<int> head_chain = tree.Chain(neck_start);
  if (head_chain.size() < 2) {
    tree.Fail("no torso chain: one weighted joint (" + tree.Name(neck_start) +
              ") above the chest; the neck and head need two");
  }
  Limb arm_a = ArmFrom(tree, arm_starts[0]);
  Limb arm_b = ArmFrom(tree, arm_starts[1]);
  Limb leg_a = LegFrom(tree, from_pelvis[1], up);
  Limb leg_b = LegFrom(tree, from_pelvis[2], up);

  // Sides: arm a is called right, and the leg on its side too; PlaceRig
  // swaps both when the feet then point backwards.
  const Vector3d lateral = tree.Position(arm_a.first) - tree.Position(arm_b.first);
  if (tree.Position(leg_a.first).dot(lateral) < tree.Position(leg_b.first).dot(lateral)) std::swap(leg_a, leg_b);

  std::map<int, int> canonical_to_rig = {{kPelvis, pelvis},
                                         {kChest, chest},
                                         {kNeck, head_chain.front()},
                                         {kHead, head_chain.back()},
                                         {kRightShoulder, arm_a.first},
                                         {kRightElbow, arm_a.middle},
                                         {kRightWrist, arm_a.last},
                                         {kLeftShoulder, arm_b.first},
                                         {kLeftElbow, arm_b.middle},
                                         {kLeftWrist, arm_b.last},
                                         {kRightHip, leg_a.first},
                                         {kRightKnee, leg_a.middle},
                                         {kRightAnkle, leg_a.last},
                                         {kLeftHip, leg_b.first},
                                         {kLeftKnee, leg_b.middle},
                                         {kLeftAnkle, leg_b.last}};
  if (spine_chain.size() >= 2) canonical_to_rig[kSpine] = spine_chain.front();
  if (arm_a.clavicle >= 0) canonical_to_rig[kRightClavicle] = arm_a.clavicle;
  if (arm_b.clavicle >= 0) canonical_to_rig[kLeftClavicle] = arm_b.clavicle;

  // The map is by name: each mapped joint's name must be the rig's only one.
  std::multiset<std::string> names(rig.joint_name.begin(), rig.joint_name.end());
  JointMapping mapping;
  mapping.convention = "hierarchy";
  for (const auto& [canonical, joint] : canonical_to_rig) {
    if (names.count(rig.joint_name[joint]) != 1) {
      tree.Fail(std::string("the joint taken for ") + JointName(canonical) + ", " + tree.Name(joint) +
                ", shares its name with another joint; name the rig's joints apart or pass a joint map");
    }
    mapping.map[JointName(canonical)] = rig.joint_name[joint];
  }
  std::set<std::string> mapped;
  for (const auto& [canonical, name] : mapping.map) mapped.insert(name);
  for (const std::string& name : rig.joint_name) {
    if (!mapped.count(name)) mapping.unmapped_rig_joints.push_back(name);
  }
  return mapping;
}

}  // namespace irbench::import_internal
