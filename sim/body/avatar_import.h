#pragma once
// Rigged meshes (glTF 2.0 with tinygltf; FBX, Collada and the rest with assimp)
// imported as avatars on the canonical skeleton.
//
// The rig's joints are mapped to the canonical joints by name (built-in tables
// of the common conventions, or the caller's map), the mesh is brought into the
// world frame (z up, metres, facing +y with its right side at +x, feet on the
// floor, pelvis over the origin), re-posed into the canonical T-pose by linear
// blend skinning with the rig's weights collapsed onto the canonical joints,
// and given the truth markers and body radii. Rules and figures in the comments
// of avatar_import.cc.

#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "sim/body/avatar.h"

namespace irbench {

// A rigged mesh's up axis as the avatar file names it ("auto", "y", "z").
enum class UpAxis { kAuto, kY, kZ };
// "auto", "y" or "z"; nullopt for another name.
std::optional<UpAxis> ParseUpAxis(const std::string& name);

struct ImportOptions {
  std::string name;  // default: the file's stem
  // Canonical joint name ("right_elbow") -> rig joint name; overrides the
  // tables. An empty rig name leaves that canonical joint unmapped.
  std::map<std::string, std::string> joint_map;
  // Metres per file unit; 0: glTF is metres, assimp formats use the file's unit
  // metadata, else centimetres are tried when the height is implausible.
  double scale = 0;
  // The file's up axis in its world frame (glTF: after the node transforms):
  // auto (the axis nearest to pelvis -> head), y or z.
  UpAxis up_axis = UpAxis::kAuto;
};

// Canonical joint name -> rig joint name (the rig's own spelling), from the
// built-in tables for a rig's joint names; `convention` names the table used
// ("irbench", "mixamo", "rigify", "makehuman", "unreal", "cesium", "generic", "daz",
// "3dsmax", "cmu"; "+overrides" appended when the caller's map changed it,
// "custom" when only the caller's map applies, "unknown" when nothing maps).
// `unmapped_rig_joints` are the rig joints no canonical joint maps to (on
// import they follow their nearest mapped ancestor).
struct JointMapping {
  std::string convention;
  std::map<std::string, std::string> map;
  std::vector<std::string> unmapped_rig_joints;
};

// Throws InputError(field "joint_map.<name>") for an override naming an unknown
// canonical joint or a rig joint that does not exist.
JointMapping MapRigJoints(const std::vector<std::string>& rig_joint_names,
                          const std::map<std::string, std::string>& overrides);

// Imports `file` (.gltf/.glb, or anything assimp reads that has a skinned
// mesh). Throws InputError(file, field, ...): "file" (missing, unreadable,
// corrupt), "skin" (no skinned mesh, no arm/torso/leg chain), "height" (outside
// 1.0..2.3 m after scaling), "scale" / "joint_map.*" (bad options).
Avatar ImportRiggedAvatar(const std::filesystem::path& file, const ImportOptions& options = {});

}  // namespace irbench
