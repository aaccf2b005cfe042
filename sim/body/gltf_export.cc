#include "sim/body/gltf_export.h"

#include <tiny_gltf.h>

#include <cstring>
#include <sstream>

#include "common/atomic_file.h"
#include "common/error.h"

namespace irbench {
namespace {

// Appends raw bytes to the buffer (4-byte aligned) and returns a view on them.
int AddView(tinygltf::Model& model, const void* data, size_t bytes, int target) {
  auto& buffer = model.buffers[0].data;
  while (buffer.size() % 4 != 0) buffer.push_back(0);
  tinygltf::BufferView view;
  view.buffer = 0;
  view.byteOffset = buffer.size();
  view.byteLength = bytes;
  view.target = target;
  const auto* p = static_cast<const unsigned char*>(data);
  buffer.insert(buffer.end(), p, p + bytes);
  model.bufferViews.push_back(view);
  return static_cast<int>(model.bufferViews.size()) - 1;
}

int AddAccessor(tinygltf::Model& model, int view, int component, int type, size_t count,
                std::vector<double> min = {}, std::vector<double> max = {}) {
  tinygltf::Accessor a;
  a.bufferView = view;
  a.componentType = component;
  a.type = type;
  a.count = count;
  a.minValues = std::move(min);
  a.maxValues = std::move(max);
  model.accessors.push_back(a);
  return static_cast<int>(model.accessors.size()) - 1;
}

}  // namespace

Eigen::Matrix3d GltfFromWorld() {
  Eigen::Matrix3d m;
  m << -1, 0, 0, 0, 0, 1, 0, 1, 0;
  return m;
}

std::string AvatarToGlb(const Avatar& avatar) {
  const Eigen::Matrix3f m = GltfFromWorld().cast<float>();
  const size_t nv = avatar.bind_vertices.size();
  std::vector<float> positions, normals, colors, weights;
  std::vector<uint8_t> joints;
  positions.reserve(3 * nv);
  Eigen::Vector3f lo = Eigen::Vector3f::Constant(1e30f), hi = -lo;
  for (size_t i = 0; i < nv; ++i) {
    const MeshVertex& v = avatar.bind_vertices[i];
    const Eigen::Vector3f p = m * v.position, n = m * v.normal;
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
    positions.insert(positions.end(), {p.x(), p.y(), p.z()});
    normals.insert(normals.end(), {n.x(), n.y(), n.z()});
    colors.insert(colors.end(), {v.albedo, v.albedo, v.albedo});
    for (int k = 0; k < 4; ++k) {
      joints.push_back(avatar.bone_index[i][k]);
      weights.push_back(avatar.bone_weight[i][k]);
    }
  }
  tinygltf::Model model;
  model.asset.version = "2.0";
  model.asset.generator = "irbench";
  model.buffers.resize(1);
  constexpr int kArray = TINYGLTF_TARGET_ARRAY_BUFFER, kIndex = TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER;
  constexpr int kFloat = TINYGLTF_COMPONENT_TYPE_FLOAT;
  tinygltf::Primitive prim;
  prim.mode = TINYGLTF_MODE_TRIANGLES;
  prim.attributes["POSITION"] =
      AddAccessor(model, AddView(model, positions.data(), positions.size() * 4, kArray), kFloat,
                  TINYGLTF_TYPE_VEC3, nv, {lo.x(), lo.y(), lo.z()}, {hi.x(), hi.y(), hi.z()});
  prim.attributes["NORMAL"] = AddAccessor(model, AddView(model, normals.data(), normals.size() * 4, kArray),
                                          kFloat, TINYGLTF_TYPE_VEC3, nv);
  prim.attributes["COLOR_0"] = AddAccessor(model, AddView(model, colors.data(), colors.size() * 4, kArray),
                                           kFloat, TINYGLTF_TYPE_VEC3, nv);
  prim.attributes["JOINTS_0"] = AddAccessor(model, AddView(model, joints.data(), joints.size(), kArray),
                                            TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, TINYGLTF_TYPE_VEC4, nv);
  prim.attributes["WEIGHTS_0"] = AddAccessor(model, AddView(model, weights.data(), weights.size() * 4, kArray),
                                             kFloat, TINYGLTF_TYPE_VEC4, nv);
  prim.indices = AddAccessor(model, AddView(model, avatar.indices.data(), avatar.indices.size() * 4, kIndex),
                             TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, TINYGLTF_TYPE_SCALAR, avatar.indices.size());
  prim.material = 0;
  tinygltf::Material material;
  material.name = "body";
  material.pbrMetallicRoughness.baseColorFactor = {1, 1, 1, 1};
  material.pbrMetallicRoughness.metallicFactor = 0;
  material.pbrMetallicRoughness.roughnessFactor = 1;
  model.materials.push_back(material);
  tinygltf::Mesh mesh;
  mesh.name = avatar.params.name;
  mesh.primitives.push_back(prim);
  model.meshes.push_back(mesh);

  // Joints 0..18 are nodes 0..18, translated from their parents in the bind
  // pose; joint frames are axis-aligned there, so each inverse bind matrix is
  // a pure translation.
  const auto& bind = avatar.skeleton.bind_position;
  std::vector<float> inverse_bind;
  tinygltf::Skin skin;
  skin.name = "canonical";
  for (int j = 0; j < kJointCount; ++j) {
    tinygltf::Node node;
    node.name = JointName(j);
    const int parent = JointParent(j);
    const Eigen::Vector3d local = GltfFromWorld() * (parent < 0 ? bind[j] : Eigen::Vector3d(bind[j] - bind[parent]));
    node.translation = {local.x(), local.y(), local.z()};
    for (int c = j + 1; c < kJointCount; ++c) {
      if (JointParent(c) == j) node.children.push_back(c);
    }
    model.nodes.push_back(node);
    skin.joints.push_back(j);
    const Eigen::Vector3d world = GltfFromWorld() * bind[j];
    const float column_major[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0,
                                    float(-world.x()), float(-world.y()), float(-world.z()), 1};
    inverse_bind.insert(inverse_bind.end(), column_major, column_major + 16);
  }
  skin.skeleton = 0;
  skin.inverseBindMatrices = AddAccessor(
      model, AddView(model, inverse_bind.data(), inverse_bind.size() * 4, 0), kFloat, TINYGLTF_TYPE_MAT4,
      kJointCount);
  model.bufferViews[model.accessors[skin.inverseBindMatrices].bufferView].target = 0;
  model.skins.push_back(skin);
  tinygltf::Node body;
  body.name = avatar.params.name;
  body.mesh = 0;
  body.skin = 0;
  model.nodes.push_back(body);
  tinygltf::Scene scene;
  scene.name = avatar.params.name;
  scene.nodes = {0, kJointCount};
  model.scenes.push_back(scene);
  model.defaultScene = 0;

  std::ostringstream out;
  tinygltf::TinyGLTF writer;
  if (!writer.WriteGltfSceneToStream(&model, out, false, true)) {
    throw RuntimeError("glTF writer failed for avatar '" + avatar.params.name + "'");
  }
  return out.str();
}

void WriteAvatarGlb(const Avatar& avatar, const std::filesystem::path& path) {
  AtomicWriteFile(path, AvatarToGlb(avatar));
}

}  // namespace irbench
