#pragma once
// Avatars: a skinned triangle mesh on the canonical skeleton, plus the truth
// points. Until the parametric body generator lands (issue 3), avatars are the
// "tube" kind: a body of tapered tubes with elliptical cross sections (torso,
// neck, head, clavicles, arms, hands, legs, feet), linear-blend skinned with
// weights that blend across every joint. Never the tracker's ellipsoids.

#include <array>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "sim/body/skeleton.h"
#include "sim/scene/mesh.h"

namespace irbench {

struct AvatarParams {
  std::string name = "p1";
  std::string kind = "tube";  // tube, parametric, mesh (imported)
  double height_m = 1.75;
  double build = 1.0;  // girth factor: 0.8 slim .. 1.4 heavy
  // Near-IR reflectance of each part at 850 and 940 nm (sim/scene/materials.h).
  NirReflectance skin_albedo = NirReflectance::Grey(0.55f);
  NirReflectance shirt_albedo = NirReflectance::Grey(0.45f);
  NirReflectance pants_albedo = NirReflectance::Grey(0.35f);
  NirReflectance shoe_albedo = NirReflectance::Grey(0.15f);
  NirReflectance hair_albedo = NirReflectance::Grey(0.25f);
  // How this person moves: fields of MotionStyle (docs/motion.md) that
  // override the seeded draw; checked by the motion library.
  nlohmann::json style = nullptr;
  // Imported meshes: where the body came from and how its rig was read (file,
  // convention, up_axis, scale, joint_map, unmapped_rig_joints).
  nlohmann::json source = nullptr;
};

struct Avatar {
  AvatarParams params;
  Skeleton skeleton;
  std::vector<MeshVertex> bind_vertices;  // bind pose
  std::vector<uint32_t> indices;
  std::vector<std::array<uint8_t, 4>> bone_index;
  std::vector<std::array<float, 4>> bone_weight;  // sums to 1
  std::vector<BoneMarker> markers;                // head centre, hand tips
  // Body radius around each truth point, metres: how deep inside the surface it
  // lies, used to tell "seen" from "hidden" by a depth test.
  std::map<std::string, double> truth_radius;
};

// Builds a tube avatar from its parameters.
Avatar BuildTubeAvatar(const AvatarParams& params);

// Loads avatars/<name>.json (format in docs/formats.md).
Avatar LoadAvatar(const std::filesystem::path& path);

// Linear blend skinning, once per frame: fills `out` (resized) with posed
// vertices and normals.
void SkinVertices(const Avatar& avatar,
                  const JointTransforms& world_from_joint,
                  std::vector<MeshVertex>& out);

// The truth joints of the data contract, in a fixed order: root, waist, neck,
// head, {left,right}_{shoulder,elbow,wrist,hand_tip,hip,knee,ankle}.
const std::vector<std::string>& TruthJointNames();
std::vector<Eigen::Vector3d> TruthJoints(const Avatar& avatar,
                                         const JointTransforms& world_from_joint);

}  // namespace irbench
