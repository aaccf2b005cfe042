// FBX, Collada and the other formats assimp reads: the skinned meshes, their
// bones and the rigid meshes hung under a joint, read into a Rig (step 1 of
// avatar_import.cc).

#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <assimp/Importer.hpp>
#include <cmath>
#include <fstream>
#include <iterator>
#include <map>
#include <set>

#include "common/error.h"
#include "common/text.h"
#include "sim/body/internal/imported_rig.h"
#include "sim/body/internal/joint_naming.h"

namespace irbench::import_internal {
namespace {

namespace fs = std::filesystem;
using Eigen::Matrix4d;
using Eigen::Vector3d;

// An assimp matrix as Eigen.
Matrix4d ToEigen(const aiMatrix4x4& m) {
  Matrix4d out;
  out << m.a1, m.a2, m.a3, m.a4, m.b1, m.b2, m.b3, m.b4, m.c1, m.c2, m.c3, m.c4, m.d1, m.d2, m.d3,
      m.d4;
  return out;
}

// World transform of `node`: its ancestors' transforms composed.
Matrix4d NodeWorld(const aiNode* node) {
  Matrix4d m = Matrix4d::Identity();
  for (const aiNode* n = node; n != nullptr; n = n->mParent) m = ToEigen(n->mTransformation) * m;
  return m;
}

// Metres per file unit into `rig` where the file says: FBX UnitScaleFactor,
// Collada (assimp applies its unit).
void ReadUnit(const aiScene* scene, const std::string& ext, Rig& rig) {
  if (ext == ".fbx" && scene->mMetaData != nullptr) {
    // FBX: UnitScaleFactor is centimetres per file unit.
    double factor = 0;
    for (unsigned i = 0; i < scene->mMetaData->mNumProperties; ++i) {
      if (std::string(scene->mMetaData->mKeys[i].C_Str()) != "UnitScaleFactor") continue;
      const aiMetadataEntry& e = scene->mMetaData->mValues[i];
      if (e.mType == AI_DOUBLE) factor = *static_cast<const double*>(e.mData);
      if (e.mType == AI_FLOAT) factor = *static_cast<const float*>(e.mData);
    }
    if (factor > 0) {
      rig.unit_scale = factor / 100.0;
      rig.unit_known = true;
    }
  } else if (ext == ".dae") {
    rig.unit_scale = 1.0;  // assimp applies <unit meter=...> to the root
    rig.unit_known = true;
  }
}

// Mesh instances: (mesh, node), depth first from `n`.
void CollectInstances(const aiNode* n, std::vector<std::pair<unsigned, const aiNode*>>& instances) {
  for (unsigned i = 0; i < n->mNumMeshes; ++i) instances.push_back({n->mMeshes[i], n});
  for (unsigned i = 0; i < n->mNumChildren; ++i) CollectInstances(n->mChildren[i], instances);
}

struct AssimpBones {
  std::map<std::string, Matrix4d> bind;  // by bone name
  std::vector<const aiNode*> nodes;
};

// The instanced meshes' bones: bind world = mesh node world x inverse(offset),
// first seen wins.
AssimpBones ReadBones(const aiScene* scene,
                      const std::vector<std::pair<unsigned, const aiNode*>>& instances,
                      const std::string& file) {
  AssimpBones bones;
  std::map<std::string, Matrix4d>& bone_bind = bones.bind;
  std::vector<const aiNode*>& bone_nodes = bones.nodes;
  for (const auto& [mesh_index, node] : instances) {
    const aiMesh* mesh = scene->mMeshes[mesh_index];
    for (unsigned b = 0; b < mesh->mNumBones; ++b) {
      const aiBone* bone = mesh->mBones[b];
      const std::string name = bone->mName.C_Str();
      if (bone_bind.count(name)) continue;
      const aiNode* bone_node = scene->mRootNode->FindNode(bone->mName);
      if (bone_node == nullptr) throw InputError(file, "skin", "bone '" + name + "' has no node");
      const Matrix4d offset = ToEigen(bone->mOffsetMatrix);
      if (std::abs(offset.determinant()) < 1e-12)
        throw InputError(file, "skin", "bone '" + name + "' has a singular offset matrix");
      bone_bind[name] = NodeWorld(node) * offset.inverse();
      bone_nodes.push_back(bone_node);
    }
  }
  if (bone_nodes.empty())
    throw InputError(file, "skin", "no skin: no mesh has bones (a rigged character is needed)");
  return bones;
}

struct AssimpJoints {
  std::set<const aiNode*> is_bone;
  std::map<const aiNode*, int> joint_of;  // index in `joints`
  std::vector<const aiNode*> joints;
};

// Adds `n` and the nodes under it that are joints (bones, and plain nodes
// other than assimp's FBX helpers), depth first.
void CollectJoints(const aiNode* n, AssimpJoints& out) {
  const std::string name = n->mName.C_Str();
  if (out.is_bone.count(n) ||
      (n->mNumMeshes == 0 && name.find("$AssimpFbx$") == std::string::npos && !name.empty())) {
    out.joint_of[n] = static_cast<int>(out.joints.size());
    out.joints.push_back(n);
  }
  for (unsigned i = 0; i < n->mNumChildren; ++i) CollectJoints(n->mChildren[i], out);
}

// Joints: the bones and the other plain nodes under their common ancestor.
AssimpJoints FindJoints(const aiScene* scene, const std::vector<const aiNode*>& bone_nodes) {
  auto path_of = [](const aiNode* n) {
    std::vector<const aiNode*> p;
    for (; n != nullptr; n = n->mParent) p.push_back(n);
    std::reverse(p.begin(), p.end());
    return p;
  };
  std::vector<const aiNode*> common = path_of(bone_nodes[0]);
  for (const aiNode* b : bone_nodes) {
    const std::vector<const aiNode*> p = path_of(b);
    size_t k = 0;
    while (k < common.size() && k < p.size() && common[k] == p[k]) ++k;
    common.resize(k);
  }
  const aiNode* top = common.empty() ? scene->mRootNode : common.back();
  AssimpJoints out;
  out.is_bone = std::set<const aiNode*>(bone_nodes.begin(), bone_nodes.end());
  CollectJoints(top, out);
  for (const aiNode* b : bone_nodes) {
    if (!out.joint_of.count(b)) {  // cannot happen (all under `top`), but keep every bone
      out.joint_of[b] = static_cast<int>(out.joints.size());
      out.joints.push_back(b);
    }
  }
  return out;
}

// Appends the joints to `rig` (name, nearest joint ancestor, bind position);
// returns their bind transforms: bones from their offsets; other joints move
// rigidly with their nearest bone ancestor, else keep their node transform.
std::vector<Matrix4d> AddAssimpJoints(AssimpJoints& j,
                                      const std::map<std::string, Matrix4d>& bone_bind,
                                      Rig& rig) {
  const std::vector<const aiNode*>& joints = j.joints;
  std::map<const aiNode*, int>& joint_of = j.joint_of;
  const std::set<const aiNode*>& is_bone = j.is_bone;
  std::vector<Matrix4d> bind(joints.size());
  for (size_t k = 0; k < joints.size(); ++k) {
    const aiNode* n = joints[k];
    rig.joint_name.push_back(n->mName.C_Str());
    const aiNode* p = n->mParent;
    while (p != nullptr && !joint_of.count(p)) p = p->mParent;
    rig.joint_parent.push_back(p != nullptr ? joint_of[p] : -1);
    const aiNode* a = n;
    while (a != nullptr && !is_bone.count(a)) a = a->mParent;
    if (a == n) {
      bind[k] = bone_bind.at(n->mName.C_Str());
    } else if (a != nullptr) {
      bind[k] = bone_bind.at(a->mName.C_Str()) * NodeWorld(a).inverse() * NodeWorld(n);
    } else {
      bind[k] = NodeWorld(n);
    }
    rig.joint_bind.push_back(bind[k].block<3, 1>(0, 3));
  }
  return bind;
}

// Appends an assimp scene's meshes to a rig: vertices, albedo, influences and
// triangles; each texture decoded once.
class AssimpMeshAdder {
 public:
  AssimpMeshAdder(const aiScene* scene,
                  const fs::path& path,
                  const std::string& file,
                  const std::map<const aiNode*, int>& joint_of,
                  Rig& rig)
      : scene_(scene), path_(path), file_(file), joint_of_(joint_of), rig_(rig) {}

  // Appends one mesh; `rigid_joint` >= 0: all its vertices on that joint.
  void AddMesh(const aiMesh* mesh, const Matrix4d& transform, int rigid_joint) {
    const uint32_t base = static_cast<uint32_t>(rig_.position.size());
    const size_t n = mesh->mNumVertices;
    std::vector<std::vector<std::pair<int, float>>> influence = ReadInfluence(mesh, n, rigid_joint);
    Eigen::Vector3f factor(1, 1, 1);
    const Texture* texture = nullptr;
    ReadBaseColour(mesh, factor, texture);
    for (size_t v = 0; v < n; ++v) {
      const aiVector3D& p = mesh->mVertices[v];
      rig_.position.push_back(Apply(transform, Vector3d(p.x, p.y, p.z)));
      Eigen::Vector3f colour = factor;
      if (texture) {
        const aiVector3D& t = mesh->mTextureCoords[0][v];
        colour = colour.cwiseProduct(Sample(*texture, t.x, 1.0 - t.y));  // assimp's v points up
      }
      rig_.albedo.push_back(AlbedoOf(colour));
      rig_.influence.push_back(std::move(influence[v]));
    }
    const bool flip =
        transform.block<3, 3>(0, 0).determinant() < 0;  // mirrored: reverse the winding
    for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
      const aiFace& face = mesh->mFaces[f];
      if (face.mNumIndices != 3) continue;  // points and lines
      for (int k : {0, flip ? 2 : 1, flip ? 1 : 2}) {
        if (face.mIndices[k] >= n) throw InputError(file_, "file", "vertex index out of range");
        rig_.indices.push_back(base + face.mIndices[k]);
      }
    }
  }

 private:
  // Per vertex (rig joint, weight) pairs from the mesh's bones, or weight 1 on
  // `rigid_joint` when it is >= 0.
  std::vector<std::vector<std::pair<int, float>>> ReadInfluence(const aiMesh* mesh,
                                                                size_t n,
                                                                int rigid_joint) const {
    std::vector<std::vector<std::pair<int, float>>> influence(n);
    if (rigid_joint >= 0) {
      for (auto& inf : influence) inf = {{rigid_joint, 1.0f}};
    } else {
      for (unsigned b = 0; b < mesh->mNumBones; ++b) {
        const aiBone* bone = mesh->mBones[b];
        const int joint = joint_of_.at(scene_->mRootNode->FindNode(bone->mName));
        for (unsigned w = 0; w < bone->mNumWeights; ++w) {
          const aiVertexWeight& vw = bone->mWeights[w];
          if (vw.mVertexId < n && vw.mWeight > 0)
            influence[vw.mVertexId].push_back({joint, vw.mWeight});
        }
      }
    }
    return influence;
  }

  // The material's base (else diffuse) colour into `factor`, and its decoded
  // texture when the mesh has UVs.
  void ReadBaseColour(const aiMesh* mesh, Eigen::Vector3f& factor, const Texture*& texture) {
    if (mesh->mMaterialIndex < scene_->mNumMaterials) {
      const aiMaterial* material = scene_->mMaterials[mesh->mMaterialIndex];
      aiColor4D c;
      if (material->Get(AI_MATKEY_BASE_COLOR, c) == AI_SUCCESS ||
          material->Get(AI_MATKEY_COLOR_DIFFUSE, c) == AI_SUCCESS) {
        factor = Eigen::Vector3f(c.r, c.g, c.b);
      }
      if (mesh->mTextureCoords[0] != nullptr) texture = TextureOf(material);
    }
  }

  // The material's base-colour (else diffuse) texture, embedded or a file
  // beside the model, decoded once; nullptr when it has none or it does not
  // decode.
  const Texture* TextureOf(const aiMaterial* material) {
    aiString tex_path;
    if (material->GetTexture(aiTextureType_BASE_COLOR, 0, &tex_path) != AI_SUCCESS &&
        material->GetTexture(aiTextureType_DIFFUSE, 0, &tex_path) != AI_SUCCESS) {
      return nullptr;
    }
    const std::string key = tex_path.C_Str();
    auto it = textures_.find(key);
    if (it == textures_.end()) {
      Texture t;
      if (const aiTexture* embedded = scene_->GetEmbeddedTexture(key.c_str())) {
        if (embedded->mHeight == 0) {  // compressed (PNG, JPEG): mWidth bytes
          t = DecodeTexture(reinterpret_cast<const unsigned char*>(embedded->pcData),
                            static_cast<int>(embedded->mWidth));
        } else {  // raw BGRA texels
          t.width = static_cast<int>(embedded->mWidth);
          t.height = static_cast<int>(embedded->mHeight);
          for (size_t p = 0; p < size_t(t.width) * t.height; ++p) {
            const aiTexel& x = embedded->pcData[p];
            t.linear.emplace_back(SrgbToLinear(x.r / 255.0f), SrgbToLinear(x.g / 255.0f),
                                  SrgbToLinear(x.b / 255.0f));
          }
        }
      } else {
        std::ifstream in(path_.parent_path() / key, std::ios::binary);
        const std::string bytes((std::istreambuf_iterator<char>(in)),
                                std::istreambuf_iterator<char>());
        t = DecodeTexture(reinterpret_cast<const unsigned char*>(bytes.data()),
                          static_cast<int>(bytes.size()));
      }
      it = textures_.emplace(key, std::move(t)).first;
    }
    return it->second.empty() ? nullptr : &it->second;
  }

  const aiScene* scene_;
  const fs::path& path_;
  const std::string& file_;
  const std::map<const aiNode*, int>& joint_of_;
  Rig& rig_;
  std::map<std::string, Texture> textures_;
};

// Appends the skinned meshes (props left out unless all are props) and the
// rigid meshes under a joint (weight 1 on it, placed by its bind transform).
void AddAssimpMeshes(const aiScene* scene,
                     const std::vector<std::pair<unsigned, const aiNode*>>& instances,
                     const std::map<const aiNode*, int>& joint_of,
                     const std::vector<Matrix4d>& bind,
                     const Rig& rig,
                     AssimpMeshAdder& meshes) {
  const bool all_skinned_are_props =
      std::all_of(instances.begin(), instances.end(), [&](const auto& instance) {
        const aiMesh* mesh = scene->mMeshes[instance.first];
        return mesh->mNumBones == 0 || IsProp(instance.second->mName.C_Str()) ||
               IsProp(mesh->mName.C_Str());
      });
  for (const auto& [mesh_index, node] : instances) {
    const aiMesh* mesh = scene->mMeshes[mesh_index];
    if (mesh->mNumBones > 0) {
      if (all_skinned_are_props || !(IsProp(node->mName.C_Str()) || IsProp(mesh->mName.C_Str()))) {
        meshes.AddMesh(mesh, NodeWorld(node), -1);
      }
      continue;
    }
    // Rigid meshes under a joint.
    bool prop = IsProp(node->mName.C_Str()) || IsProp(mesh->mName.C_Str());
    const aiNode* a = node;
    while (a != nullptr && !joint_of.count(a)) {
      prop = prop || IsProp(a->mName.C_Str());
      a = a->mParent;
    }
    if (a == nullptr || a == scene->mRootNode) continue;
    const int joint = joint_of.at(a);
    if (prop || IsProp(rig.joint_name[joint])) continue;
    meshes.AddMesh(mesh, Matrix4d(bind[joint] * NodeWorld(a).inverse() * NodeWorld(node)), joint);
  }
}

}  // namespace

Rig LoadAssimp(const fs::path& path) {
  const std::string file = path.string();
  Assimp::Importer importer;
  const aiScene* scene = importer.ReadFile(
      file, aiProcess_Triangulate | aiProcess_LimitBoneWeights | aiProcess_JoinIdenticalVertices);
  if (scene == nullptr || scene->mRootNode == nullptr) {
    throw InputError(file, "file",
                     std::string("not a readable model: ") + importer.GetErrorString());
  }
  std::string ext = AsciiLower(path.extension().string());
  Rig rig;
  rig.format = ext;
  ReadUnit(scene, ext, rig);

  // Mesh instances: (mesh, node).
  std::vector<std::pair<unsigned, const aiNode*>> instances;
  CollectInstances(scene->mRootNode, instances);
  if (scene->mNumMeshes == 0) throw InputError(file, "skin", "no mesh in the file");

  const AssimpBones bones = ReadBones(scene, instances, file);
  AssimpJoints joints = FindJoints(scene, bones.nodes);
  const std::vector<Matrix4d> bind = AddAssimpJoints(joints, bones.bind, rig);

  AssimpMeshAdder meshes(scene, path, file, joints.joint_of, rig);
  AddAssimpMeshes(scene, instances, joints.joint_of, bind, rig, meshes);
  return rig;
}

}  // namespace irbench::import_internal
