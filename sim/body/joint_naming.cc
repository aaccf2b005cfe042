// Rig joint names -> canonical joints: the built-in tables of the common
// skeleton conventions (Mixamo, rigify, MakeHuman, Unreal, DAZ, ...), the
// name normalisation they are matched under, and the caller's overrides.

#include "sim/body/internal/joint_naming.h"

#include <cctype>
#include <cstring>
#include <set>
#include <unordered_map>
#include <utility>

#include "common/error.h"
#include "common/text.h"
#include "sim/body/avatar.h"

namespace irbench::import_internal {

namespace {

// Whether `s` starts with `prefix` and is longer than it.
bool StartsWith(const std::string& s, const std::string& prefix) {
  return s.size() > prefix.size() && s.compare(0, prefix.size(), prefix) == 0;
}

// Lower case, namespace ("mixamorig:", "Character1:") and common prefixes
// stripped, '.', '-' and ' ' as '_'.
std::string NormaliseJointName(const std::string& name) {
  std::string s = AsciiLower(name);
  const size_t colon = s.rfind(':');
  if (colon != std::string::npos && colon + 1 < s.size()) s = s.substr(colon + 1);
  for (char& c : s) {
    if (c == '.' || c == '-' || c == ' ') c = '_';
  }
  static const char* kPrefixes[] = {"mixamorig_", "mixamorig1_", "mixamorig2_",
                                    "armature_",  "skeleton_",   "def_",
                                    "org_",       "bip01_",      "bip001_"};
  for (bool again = true; again;) {
    again = false;
    for (const char* p : kPrefixes) {
      if (StartsWith(s, p)) {
        s = s.substr(std::strlen(p));
        again = true;
      }
    }
  }
  return s;
}

// A table maps a key to alternatives, tried in order. Keys: an unsided
// canonical joint ("pelvis"), a sided one ("left_shoulder": literal names for
// that side only) or a side-less limb key ("shoulder": both sides). A limb
// key's alternative is a base name matched in every usual side spelling
// (upper_arm_l, upper_arm_left, l_upper_arm, left_upper_arm, leftupper_arm,
// upper_armleft) unless it holds "{s}" (l/r) or "{side}" (left/right), which
// are substituted literally. Names are compared normalised.
struct Convention {
  const char* name;
  std::vector<std::pair<std::string, std::vector<std::string>>> entries;
};

// The built-in tables, the specific conventions before "generic".
const std::vector<Convention>& Conventions() {
  // Order breaks ties: the specific tables before "generic".
  static const std::vector<Convention> tables = {
      {"irbench",  // our own glTF export (irbench avatar export): the canonical names
       [] {
         std::vector<std::pair<std::string, std::vector<std::string>>> entries;
         for (int j = 0; j < kJointCount; ++j) entries.push_back({JointName(j), {JointName(j)}});
         return entries;
       }()},
      {"cesium",  // Cesium's sample rigs: CesiumMan, RiggedFigure (Khronos glTF samples)
       {{"pelvis", {"torso_joint_1"}},
        {"spine", {"torso_joint_2"}},
        {"chest", {"torso_joint_3"}},
        {"neck", {"neck_joint_1"}},
        {"head", {"neck_joint_2"}},
        {"left_shoulder", {"arm_joint_l__4_", "arm_joint_l_1"}},
        {"left_elbow", {"arm_joint_l__3_", "arm_joint_l_2"}},
        {"left_wrist", {"arm_joint_l__2_", "arm_joint_l_3"}},
        {"right_shoulder", {"arm_joint_r", "arm_joint_r_1"}},
        {"right_elbow", {"arm_joint_r__2_", "arm_joint_r_2"}},
        {"right_wrist", {"arm_joint_r__3_", "arm_joint_r_3"}},
        {"hip", {"leg_joint_{s}_1"}},
        {"knee", {"leg_joint_{s}_2"}},
        {"ankle", {"leg_joint_{s}_3"}}}},
      {"mixamo",  // also the CMU BVH conversions (cgspeed) and MotionBuilder
       {{"pelvis", {"hips"}},
        {"spine", {"spine"}},
        {"chest", {"spine2", "spine1"}},
        {"neck", {"neck"}},
        {"head", {"head"}},
        {"clavicle", {"shoulder"}},
        {"shoulder", {"arm"}},
        {"elbow", {"forearm"}},
        {"wrist", {"hand"}},
        {"hip", {"upleg"}},
        {"knee", {"leg"}},
        {"ankle", {"foot"}}}},
      {"rigify",  // Blender rigify (DEF-/ORG- stripped)
       {{"pelvis", {"spine"}},
        {"spine", {"spine_001"}},
        {"chest", {"spine_002", "spine_003"}},
        {"neck", {"spine_004"}},
        {"head", {"spine_006", "spine_005"}},
        {"clavicle", {"shoulder"}},
        {"shoulder", {"upper_arm"}},
        {"elbow", {"forearm"}},
        {"wrist", {"hand"}},
        {"hip", {"thigh"}},
        {"knee", {"shin"}},
        {"ankle", {"foot"}}}},
      {"makehuman",  // MakeHuman default rig
       {{"pelvis", {"pelvis", "root"}},
        {"spine", {"spine05", "spine04"}},
        {"chest", {"spine03", "spine02"}},
        {"neck", {"neck01"}},
        {"head", {"head"}},
        {"clavicle", {"clavicle"}},
        {"shoulder", {"upperarm01", "upperarm"}},
        {"elbow", {"lowerarm01", "lowerarm"}},
        {"wrist", {"wrist", "hand"}},
        {"hip", {"upperleg01", "thigh"}},
        {"knee", {"lowerleg01", "shin", "calf"}},
        {"ankle", {"foot"}}}},
      {"unreal",  // Unreal mannequin, MakeHuman game engine rig
       {{"pelvis", {"pelvis"}},
        {"spine", {"spine_01"}},
        {"chest", {"spine_03", "spine_02"}},
        {"neck", {"neck_01"}},
        {"head", {"head"}},
        {"clavicle", {"clavicle"}},
        {"shoulder", {"upperarm"}},
        {"elbow", {"lowerarm"}},
        {"wrist", {"hand"}},
        {"hip", {"thigh"}},
        {"knee", {"calf"}},
        {"ankle", {"foot"}}}},
      {"daz",  // DAZ / Poser BVH
       {{"pelvis", {"hip"}},
        {"spine", {"abdomen"}},
        {"chest", {"chest"}},
        {"neck", {"neck"}},
        {"head", {"head"}},
        {"clavicle", {"{s}collar"}},
        {"shoulder", {"{s}shldr"}},
        {"elbow", {"{s}forearm"}},
        {"wrist", {"{s}hand"}},
        {"hip", {"{s}thigh"}},
        {"knee", {"{s}shin"}},
        {"ankle", {"{s}foot"}}}},
      {"3dsmax",  // 3ds Max biped BVH export
       {{"pelvis", {"hips"}},
        {"spine", {"chest"}},
        {"chest", {"chest2"}},
        {"neck", {"neck"}},
        {"head", {"head"}},
        {"clavicle", {"collar"}},
        {"shoulder", {"shoulder"}},
        {"elbow", {"elbow"}},
        {"wrist", {"wrist"}},
        {"hip", {"hip"}},
        {"knee", {"knee"}},
        {"ankle", {"ankle"}}}},
      {"cmu",  // raw CMU ASF/AMC bone names (a joint at its bone's start), as in retarget.cc
       {{"pelvis", {"root", "hip"}},
        {"spine", {"upperback", "lowerback"}},
        {"chest", {"thorax"}},
        {"neck", {"upperneck", "lowerneck"}},
        {"head", {"head"}},
        {"clavicle", {"{s}clavicle"}},
        {"shoulder", {"{s}humerus"}},
        {"elbow", {"{s}radius"}},
        {"wrist", {"{s}wrist", "{s}hand"}},
        {"hip", {"{s}femur"}},
        {"knee", {"{s}tibia"}},
        {"ankle", {"{s}foot"}}}},
      {"generic",  // Blender metarig, Quaternius, 3ds Max biped (Bip01 stripped), others
       {{"pelvis", {"hips", "pelvis", "hip"}},
        {"spine", {"spine", "abdomen", "spine1", "spine_01", "spine01", "lowerback", "waist"}},
        {"chest",
         {"chest", "torso", "spine2", "spine_02", "spine02", "upperchest", "upper_chest",
          "thorax"}},
        {"neck", {"neck", "neck1", "neck_01", "neck01"}},
        {"head", {"head"}},
        {"clavicle", {"clavicle", "shoulder", "collar"}},
        {"shoulder", {"upper_arm", "upperarm", "arm"}},
        {"elbow", {"forearm", "lowerarm", "lower_arm", "fore_arm", "elbow"}},
        {"wrist", {"hand", "fist", "wrist"}},
        {"hip", {"thigh", "upperleg", "upper_leg", "upleg", "hip"}},
        {"knee", {"shin", "lowerleg", "lower_leg", "calf", "leg", "knee"}},
        {"ankle", {"foot", "ankle"}}}},
  };
  return tables;
}

// The side-less limb key of a sided joint ("elbow"); nullptr for the others.
const char* LimbKey(int joint) {
  switch (joint) {
    case kRightClavicle:
    case kLeftClavicle:
      return "clavicle";
    case kRightShoulder:
    case kLeftShoulder:
      return "shoulder";
    case kRightElbow:
    case kLeftElbow:
      return "elbow";
    case kRightWrist:
    case kLeftWrist:
      return "wrist";
    case kRightHip:
    case kLeftHip:
      return "hip";
    case kRightKnee:
    case kLeftKnee:
      return "knee";
    case kRightAnkle:
    case kLeftAnkle:
      return "ankle";
    default:
      return nullptr;
  }
}

// Whether canonical `joint` is on the left side.
bool IsLeft(int joint) {
  return std::string(JointName(joint)).rfind("left_", 0) == 0;
}

// "{side}" and "{s}" replaced by left/right and l/r.
std::string Substitute(std::string s, bool left) {
  for (const auto& [key, value] :
       {std::pair<std::string, std::string>{"{side}", left ? "left" : "right"},
        std::pair<std::string, std::string>{"{s}", left ? "l" : "r"}}) {
    for (size_t pos; (pos = s.find(key)) != std::string::npos;) s.replace(pos, key.size(), value);
  }
  return s;
}

// Normalised candidate names for canonical `joint` in `table`, best first.
std::vector<std::string> Candidates(const Convention& table, int joint) {
  std::vector<std::string> out;
  const char* limb = LimbKey(joint);
  const bool left = IsLeft(joint);
  for (const auto& [key, alternatives] : table.entries) {
    if (key == JointName(joint)) {
      for (const std::string& a : alternatives) out.push_back(Substitute(a, left));
    } else if (limb != nullptr && key == limb) {
      for (const std::string& a : alternatives) {
        if (a.find('{') != std::string::npos) {
          out.push_back(Substitute(a, left));
          continue;
        }
        const std::string l = left ? "l" : "r", word = left ? "left" : "right";
        for (const std::string& form :
             {a + "_" + l, a + "_" + word, l + "_" + a, word + "_" + a, word + a, a + word}) {
          out.push_back(form);
        }
      }
    }
  }
  return out;
}

// Whether an import needs canonical `joint` mapped (spine, chest and clavicles
// are interpolated).
bool IsRequired(int joint) {
  return joint != kSpine && joint != kChest && joint != kRightClavicle && joint != kLeftClavicle;
}

}  // namespace

std::string JoinNames(const std::vector<std::string>& names, size_t limit) {
  std::string out;
  for (size_t i = 0; i < names.size() && i < limit; ++i) out += (i ? ", " : "") + names[i];
  if (names.size() > limit) out += ", … (" + std::to_string(names.size()) + " in all)";
  return out;
}

JointMapping MapJoints(const std::vector<std::string>& rig_names,
                       const std::map<std::string, std::string>& overrides,
                       const std::string& file) {
  std::unordered_map<std::string, std::string> by_normalised;  // first rig name per normalised name
  for (const std::string& name : rig_names) by_normalised.emplace(NormaliseJointName(name), name);

  JointMapping best;
  best.convention = "unknown";
  int best_score = 0;
  for (const Convention& table : Conventions()) {
    std::map<std::string, std::string> map;
    std::set<std::string> used;
    int score = 0;
    for (int j = 0; j < kJointCount; ++j) {
      for (const std::string& candidate : Candidates(table, j)) {
        const auto it = by_normalised.find(candidate);
        if (it == by_normalised.end() || used.count(it->second)) continue;
        map[JointName(j)] = it->second;
        used.insert(it->second);
        score += IsRequired(j) ? 100 : 1;
        break;
      }
    }
    if (score > best_score) {
      best_score = score;
      best.convention = table.name;
      best.map = std::move(map);
    }
  }

  for (const auto& [canonical, rig] : overrides) {
    const std::string field = "joint_map." + canonical;
    if (!JointFromName(canonical)) {
      std::vector<std::string> names;
      for (int j = 0; j < kJointCount; ++j) names.push_back(JointName(j));
      throw InputError(file, field, "unknown canonical joint (" + JoinNames(names) + ")");
    }
    if (rig.empty()) {
      best.map.erase(canonical);
      continue;
    }
    std::string found;
    for (const std::string& name : rig_names) {
      if (name == rig) {
        found = name;
        break;
      }
    }
    if (found.empty()) {
      for (const std::string& name : rig_names) {
        if (AsciiLower(name) == AsciiLower(rig) || NormaliseJointName(name) == NormaliseJointName(rig)) {
          found = name;
          break;
        }
      }
    }
    if (found.empty()) {
      throw InputError(
          file, field,
          "the rig has no joint named '" + rig + "' (rig joints: " + JoinNames(rig_names) + ")");
    }
    for (auto it = best.map.begin(); it != best.map.end();) {  // the override takes the rig joint
      it = it->second == found && it->first != canonical ? best.map.erase(it) : std::next(it);
    }
    best.map[canonical] = found;
  }
  if (!overrides.empty())
    best.convention = best.convention == "unknown" ? "custom" : best.convention + "+overrides";

  std::set<std::string> mapped;
  for (const auto& [canonical, rig] : best.map) mapped.insert(rig);
  for (const std::string& name : rig_names) {
    if (!mapped.count(name)) best.unmapped_rig_joints.push_back(name);
  }
  return best;
}

}  // namespace irbench::import_internal

namespace irbench {

JointMapping MapRigJoints(const std::vector<std::string>& rig_joint_names,
                          const std::map<std::string, std::string>& overrides) {
  return import_internal::MapJoints(rig_joint_names, overrides, "");
}

}  // namespace irbench
