#pragma once
// Avatars as binary glTF 2.0 (.glb): the bind mesh with normals and grey
// albedo (COLOR_0), the canonical skeleton as a node hierarchy, and the skin
// (JOINTS_0 / WEIGHTS_0 with inverse bind matrices). glTF is y up, facing +z:
// world (x, y, z) is written as (-x, z, y). Blender (File > Import > glTF 2.0),
// three.js and any glTF viewer open it.

#include <filesystem>
#include <string>

#include "sim/body/avatar.h"

namespace irbench {

// The .glb bytes.
std::string AvatarToGlb(const Avatar& avatar);

// Writes the .glb atomically.
void WriteAvatarGlb(const Avatar& avatar, const std::filesystem::path& path);

// World (z up, facing +y) to glTF (y up, facing +z), its own inverse.
Eigen::Matrix3d GltfFromWorld();

}  // namespace irbench
