#pragma once
// Private to the avatar importer: the rig the format loaders read
// (gltf_import.cc, assimp_import.cc), in the file's world frame and units, and
// what the loaders share (imported_rig.cc).

#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

namespace tinygltf {
struct Image;
}  // namespace tinygltf

namespace irbench::import_internal {

struct Texture {
  int width = 0, height = 0;
  std::vector<Eigen::Vector3f> linear;  // linear RGB, row 0 at the top
  bool empty() const { return linear.empty(); }
};

struct Rig {
  std::vector<std::string> joint_name;
  std::vector<int> joint_parent;            // nearest ancestor that is a joint; -1
  std::vector<Eigen::Vector3d> joint_bind;  // bind position
  std::vector<Eigen::Vector3d> position;    // vertices, bind pose
  std::vector<float> albedo;                // per vertex
  std::vector<uint32_t> indices;
  std::vector<std::vector<std::pair<int, float>>> influence;  // rig joint, weight
  double unit_scale = 1.0;                                    // metres per unit
  bool unit_known = false;
  std::string format;
};

// Whether a node, mesh or joint name looks like a prop (weapon, staff, ...).
bool IsProp(const std::string& name);

// sRGB-encoded channel in [0, 1] -> linear.
float SrgbToLinear(float c);

// A decoded tinygltf image (1..4 components, 8 or 16 bits, sRGB) -> linear RGB.
Texture MakeTexture(const tinygltf::Image& image);

// Decodes PNG/JPEG bytes with tinygltf's stb decoder; empty when it cannot.
Texture DecodeTexture(const unsigned char* bytes, int size);

// Bilinear, repeating; (u, v) with v = 0 at the top row.
Eigen::Vector3f Sample(const Texture& t, double u, double v);

// 0.8 x Rec. 709 luminance of a linear RGB colour, clamped to [0, 1].
float AlbedoOf(const Eigen::Vector3f& linear_rgb);

// The affine 4x4 `m` applied to the point `p`.
Eigen::Vector3d Apply(const Eigen::Matrix4d& m, const Eigen::Vector3d& p);

// Loads a .gltf/.glb file's skin 0 (gltf_import.cc). Throws InputError.
Rig LoadGltf(const std::filesystem::path& path);

// Loads any file assimp reads with a skinned mesh (assimp_import.cc). Throws
// InputError.
Rig LoadAssimp(const std::filesystem::path& path);

}  // namespace irbench::import_internal
