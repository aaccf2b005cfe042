#include "sim/body/gltf_export.h"

#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <gtest/gtest.h>
#include <tiny_gltf.h>

#include <filesystem>
#include <fstream>

#include "sim/body/parametric.h"

namespace irbench {
namespace {
namespace fs = std::filesystem;

// Exported glTF re-imports with tinygltf and with assimp with every joint and
// the bind pose within 1e-5 m.
TEST(GltfExportTest, ReimportsWithTinygltfAndAssimp) {
  AvatarParams params;
  params.name = "export_test";
  params.height_m = 1.68;
  BodyShape shape;
  shape.clothing = "loose_shirt";
  const Avatar avatar = BuildParametricAvatar(params, shape);
  const fs::path file = fs::temp_directory_path() / "irbench_export_test.glb";
  WriteAvatarGlb(avatar, file);
  const Eigen::Matrix3d m = GltfFromWorld();

  // tinygltf: the node hierarchy's translations give the bind pose.
  tinygltf::Model model;
  tinygltf::TinyGLTF loader;
  std::string err, warn;
  ASSERT_TRUE(loader.LoadBinaryFromFile(&model, &err, &warn, file.string())) << err;
  ASSERT_EQ(model.skins.size(), 1u);
  const auto& joints = model.skins[0].joints;
  ASSERT_EQ(joints.size(), static_cast<size_t>(kJointCount));
  std::vector<Eigen::Vector3d> world(model.nodes.size(), Eigen::Vector3d::Zero());
  std::vector<int> parent(model.nodes.size(), -1);
  for (size_t n = 0; n < model.nodes.size(); ++n) {
    for (int c : model.nodes[n].children) parent[c] = static_cast<int>(n);
  }
  double worst = 0;
  for (int j = 0; j < kJointCount; ++j) {
    const int node = joints[j];
    EXPECT_EQ(model.nodes[node].name, JointName(j));
    Eigen::Vector3d p = Eigen::Vector3d::Zero();
    for (int n = node; n >= 0; n = parent[n]) {
      const auto& t = model.nodes[n].translation;
      if (t.size() == 3) p += Eigen::Vector3d(t[0], t[1], t[2]);
    }
    worst = std::max(worst, (p - m * avatar.skeleton.bind_position[j]).norm());
  }
  EXPECT_LT(worst, 1e-5);
  const auto& prim = model.meshes.at(0).primitives.at(0);
  EXPECT_EQ(model.accessors[prim.attributes.at("POSITION")].count, avatar.bind_vertices.size());
  EXPECT_EQ(model.accessors[prim.indices].count, avatar.indices.size());

  // assimp: every joint is a node and a bone; the inverse of each bone's
  // offset matrix is its bind pose.
  Assimp::Importer importer;
  const aiScene* scene = importer.ReadFile(file.string(), 0);
  ASSERT_NE(scene, nullptr) << importer.GetErrorString();
  ASSERT_EQ(scene->mNumMeshes, 1u);
  const aiMesh* mesh = scene->mMeshes[0];
  EXPECT_EQ(mesh->mNumVertices, avatar.bind_vertices.size());
  EXPECT_EQ(mesh->mNumBones, static_cast<unsigned>(kJointCount));
  double worst_assimp = 0;
  for (unsigned b = 0; b < mesh->mNumBones; ++b) {
    const aiBone* bone = mesh->mBones[b];
    const auto joint = JointFromName(bone->mName.C_Str());
    ASSERT_TRUE(joint.has_value()) << bone->mName.C_Str();
    EXPECT_NE(scene->mRootNode->FindNode(bone->mName), nullptr);
    aiMatrix4x4 bind = bone->mOffsetMatrix;
    bind.Inverse();
    const Eigen::Vector3d p(bind.a4, bind.b4, bind.c4);
    worst_assimp = std::max(worst_assimp, (p - m * avatar.skeleton.bind_position[*joint]).norm());
  }
  EXPECT_LT(worst_assimp, 1e-5);
  std::printf("glTF re-import: %d joints, bind pose within %.1e m (tinygltf), %.1e m (assimp)\n", kJointCount,
              worst, worst_assimp);
  fs::remove(file);
}

}  // namespace
}  // namespace irbench
