// glTF 2.0 rigs (tinygltf): skin 0, the meshes it skins and the rigid meshes
// hung under its joints, read into a Rig (step 1 of avatar_import.cc).

// tinygltf: the Debian shared library (TinyGLTF::TinyGLTF, built with stb and
// nlohmann json), as gltf_export.cc uses it; no TINYGLTF_IMPLEMENTATION here.
#include <tiny_gltf.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <fstream>
#include <map>

#include "common/error.h"
#include "common/logging.h"
#include "sim/body/internal/imported_rig.h"

namespace irbench::import_internal {
namespace {

namespace fs = std::filesystem;
using Eigen::Matrix4d;
using Eigen::Vector3d;

// tinygltf image callback: its own stb decoder, but a texture that does not
// decode leaves the image empty (the material colour is used) instead of
// failing the whole file.
bool DecodeGltfImage(tinygltf::Image* image,
                     const int index,
                     std::string*,
                     std::string* warn,
                     int width,
                     int height,
                     const unsigned char* bytes,
                     int size,
                     void*) {
  std::string err;
  if (!tinygltf::LoadImageData(image, index, &err, warn, width, height, bytes, size, nullptr)) {
    if (warn)
      *warn +=
          "image '" + image->name + "' does not decode (" + err + "); using the material colour\n";
    image->image.clear();
  }
  return true;
}

// Reads glTF accessors; every failure is InputError(file, "file").
class GltfReader {
 public:
  GltfReader(const tinygltf::Model& model, std::string file) : m_(model), file_(std::move(file)) {}

  // Accessor `index` as doubles, `components` per element (checked); integer
  // components are scaled to [0, 1] when the accessor is normalised or
  // `normalise` is set (glTF weights), else read as integers.
  std::vector<double> Read(int index,
                           int components,
                           const std::string& what,
                           bool normalise = false) const {
    if (index < 0 || index >= static_cast<int>(m_.accessors.size()))
      Fail(what + ": no accessor " + std::to_string(index));
    const tinygltf::Accessor& a = m_.accessors[index];
    if (a.sparse.isSparse) Fail(what + ": sparse accessors are not supported");
    const int n = tinygltf::GetNumComponentsInType(static_cast<uint32_t>(a.type));
    if (n != components)
      Fail(what + ": expected " + std::to_string(components) + " components, got " +
           std::to_string(n));
    const int size = tinygltf::GetComponentSizeInBytes(static_cast<uint32_t>(a.componentType));
    if (size <= 0) Fail(what + ": bad component type " + std::to_string(a.componentType));
    // Sizes are checked before anything is allocated from the claimed count
    // (ValidateGltfSizes did so for the whole file already).
    if (a.bufferView < 0) return std::vector<double>(a.count * static_cast<size_t>(n), 0.0);
    if (a.bufferView >= static_cast<int>(m_.bufferViews.size())) Fail(what + ": bad buffer view");
    const tinygltf::BufferView& view = m_.bufferViews[a.bufferView];
    if (view.buffer < 0 || view.buffer >= static_cast<int>(m_.buffers.size()))
      Fail(what + ": bad buffer");
    const std::vector<unsigned char>& data = m_.buffers[view.buffer].data;
    const int stride = a.ByteStride(view);
    if (stride <= 0) Fail(what + ": bad byte stride");
    const size_t begin = view.byteOffset + a.byteOffset;
    const size_t limit = std::min<size_t>(view.byteOffset + view.byteLength, data.size());
    const size_t element = size_t(n) * size;
    if (a.count > 0 && (begin + element > limit ||
                        (a.count - 1) > (limit - begin - element) / static_cast<size_t>(stride))) {
      throw InputError(file_, "accessors[" + std::to_string(index) + "].count",
                       what + ": accessor " + std::to_string(index) + " runs past its buffer");
    }
    std::vector<double> out(a.count * static_cast<size_t>(n), 0.0);
    const bool scale = a.normalized || normalise;
    for (size_t k = 0; k < a.count; ++k) {
      const unsigned char* p = data.data() + begin + k * stride;
      for (int c = 0; c < n; ++c) {
        const unsigned char* q = p + c * size;
        double v = 0;
        switch (a.componentType) {
          case TINYGLTF_COMPONENT_TYPE_FLOAT: {
            float f;
            std::memcpy(&f, q, 4);
            v = f;
            break;
          }
          case TINYGLTF_COMPONENT_TYPE_DOUBLE: {
            double d;
            std::memcpy(&d, q, 8);
            v = d;
            break;
          }
          case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
            v = *q;
            if (scale) v /= 255.0;
            break;
          case TINYGLTF_COMPONENT_TYPE_BYTE: {
            int8_t i;
            std::memcpy(&i, q, 1);
            v = scale ? std::max(i / 127.0, -1.0) : i;
            break;
          }
          case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
            uint16_t i;
            std::memcpy(&i, q, 2);
            v = scale ? i / 65535.0 : i;
            break;
          }
          case TINYGLTF_COMPONENT_TYPE_SHORT: {
            int16_t i;
            std::memcpy(&i, q, 2);
            v = scale ? std::max(i / 32767.0, -1.0) : i;
            break;
          }
          case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: {
            uint32_t i;
            std::memcpy(&i, q, 4);
            v = scale ? i / 4294967295.0 : i;
            break;
          }
          case TINYGLTF_COMPONENT_TYPE_INT: {
            int32_t i;
            std::memcpy(&i, q, 4);
            v = i;
            break;
          }
          default:
            Fail(what + ": bad component type");
        }
        out[k * n + c] = v;
      }
    }
    return out;
  }

  [[noreturn]] void Fail(const std::string& message) const {
    throw InputError(file_, "file", message);
  }

 private:
  const tinygltf::Model& m_;
  std::string file_;
};

// A node's local transform: its matrix, else translation x rotation x scale.
Matrix4d NodeLocal(const tinygltf::Node& node) {
  Matrix4d m = Matrix4d::Identity();
  if (node.matrix.size() == 16) {
    for (int i = 0; i < 16; ++i) m(i % 4, i / 4) = node.matrix[i];
    return m;
  }
  const Vector3d t = node.translation.size() == 3
                         ? Vector3d(node.translation[0], node.translation[1], node.translation[2])
                         : Vector3d::Zero();
  Eigen::Quaterniond q = node.rotation.size() == 4
                             ? Eigen::Quaterniond(node.rotation[3], node.rotation[0],
                                                  node.rotation[1], node.rotation[2])
                             : Eigen::Quaterniond::Identity();
  if (q.norm() > 0) q.normalize();
  const Vector3d s = node.scale.size() == 3 ? Vector3d(node.scale[0], node.scale[1], node.scale[2])
                                            : Vector3d::Ones();
  m.block<3, 3>(0, 0) = q.toRotationMatrix() * s.asDiagonal();
  m.block<3, 1>(0, 3) = t;
  return m;
}

// Sizes every buffer view and accessor claims, against the bytes that are
// there, before anything is allocated from them: a view must lie inside its
// buffer, an accessor's `count` elements (at its stride) inside its view, and
// an accessor without a view (zeros) may not claim more elements than the
// input has bytes (`file_bytes` plus its buffers). InputError names the field
// ("accessors[3].count"). tinygltf itself allocates only what the file holds.
void ValidateGltfSizes(const tinygltf::Model& model,
                       const std::string& file,
                       uintmax_t file_bytes) {
  uintmax_t input_bytes = file_bytes;
  for (const tinygltf::Buffer& buffer : model.buffers) input_bytes += buffer.data.size();
  for (size_t i = 0; i < model.bufferViews.size(); ++i) {
    const tinygltf::BufferView& view = model.bufferViews[i];
    const std::string field = "bufferViews[" + std::to_string(i) + "]";
    if (view.buffer < 0 || view.buffer >= static_cast<int>(model.buffers.size()))
      throw InputError(file, field + ".buffer", "no buffer " + std::to_string(view.buffer));
    const size_t buffer_bytes = model.buffers[view.buffer].data.size();
    if (view.byteOffset > buffer_bytes || view.byteLength > buffer_bytes - view.byteOffset) {
      throw InputError(file, field + ".byteLength",
                       "bytes " + std::to_string(view.byteOffset) + " + " +
                           std::to_string(view.byteLength) + " run past buffer " +
                           std::to_string(view.buffer) + " (" + std::to_string(buffer_bytes) +
                           " bytes)");
    }
  }
  for (size_t i = 0; i < model.accessors.size(); ++i) {
    const tinygltf::Accessor& a = model.accessors[i];
    const std::string field = "accessors[" + std::to_string(i) + "]";
    const int components = tinygltf::GetNumComponentsInType(static_cast<uint32_t>(a.type));
    const int component_bytes =
        tinygltf::GetComponentSizeInBytes(static_cast<uint32_t>(a.componentType));
    if (components <= 0) throw InputError(file, field + ".type", "unknown accessor type");
    if (component_bytes <= 0)
      throw InputError(file, field + ".componentType", "unknown component type");
    const uintmax_t element = uintmax_t(components) * component_bytes;
    const std::string claim =
        "claims " + std::to_string(a.count) + " elements of " + std::to_string(element) + " bytes";
    if (a.bufferView < 0) {
      if (a.count > input_bytes)
        throw InputError(file, field + ".count",
                         claim + "; the whole input has " + std::to_string(input_bytes) + " bytes");
      continue;
    }
    if (a.bufferView >= static_cast<int>(model.bufferViews.size()))
      throw InputError(file, field + ".bufferView",
                       "no buffer view " + std::to_string(a.bufferView));
    const tinygltf::BufferView& view = model.bufferViews[a.bufferView];
    const int stride = a.ByteStride(view);
    if (stride <= 0)
      throw InputError(file, "bufferViews[" + std::to_string(a.bufferView) + "].byteStride",
                       "bad byte stride");
    if (a.count == 0) continue;
    const uintmax_t view_bytes = view.byteLength;
    if (a.byteOffset > view_bytes || element > view_bytes - a.byteOffset ||
        (a.count - 1) > (view_bytes - a.byteOffset - element) / uintmax_t(stride)) {
      throw InputError(file, field + ".count",
                       claim + " (stride " + std::to_string(stride) + ") from byte " +
                           std::to_string(a.byteOffset) + "; buffer view " +
                           std::to_string(a.bufferView) + " holds " + std::to_string(view_bytes) +
                           " bytes");
    }
  }
}

// Reads `path` into `model` (binary glTF when it starts with "glTF"); throws
// InputError(file, "file") when tinygltf cannot read it.
void ReadGltfModel(const fs::path& path, const std::string& file, tinygltf::Model& model) {
  std::string magic(4, '\0');
  {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw InputError(file, "file", "cannot open");
    in.read(magic.data(), 4);
  }
  tinygltf::TinyGLTF loader;
  loader.SetImageLoader(&DecodeGltfImage, nullptr);
  std::string err, warn;
  bool ok = false;
  try {
    ok = magic == "glTF" ? loader.LoadBinaryFromFile(&model, &err, &warn, file)
                         : loader.LoadASCIIFromFile(&model, &err, &warn, file);
  } catch (const std::exception& e) {
    err = e.what();
  }
  auto trim = [](std::string s) {
    while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.pop_back();
    return s;
  };
  if (!ok)
    throw InputError(
        file, "file",
        "not a readable glTF file: " + (err.empty() ? std::string("unknown error") : trim(err)));
  if (!warn.empty()) Log().debug("avatar import: {}: {}", file, trim(warn));
  std::error_code ec;
  const uintmax_t file_bytes = fs::file_size(path, ec);
  ValidateGltfSizes(model, file, ec ? 0 : file_bytes);
}

// The node hierarchy: each node's parent (-1 for a root), checked on
// construction, and its world transform, computed on first use.
class GltfNodeTree {
 public:
  GltfNodeTree(const tinygltf::Model& model, const GltfReader& reader, int node_count)
      : model_(model), reader_(reader), parent_(node_count, -1) {
    for (int i = 0; i < node_count; ++i) {
      for (int c : model_.nodes[i].children) {
        if (c < 0 || c >= node_count || parent_[c] >= 0 || c == i)
          reader_.Fail("node " + std::to_string(i) + ": bad child " + std::to_string(c));
        parent_[c] = i;
      }
    }
    world_.resize(node_count);
    state_.assign(node_count, 0);
  }

  // Parent node of node `i`; -1 for a root.
  int Parent(int i) const { return parent_[i]; }

  // World transform of node `i`: its ancestors' local transforms composed.
  // Iterative, so that a deep node chain cannot overflow the stack.
  const Matrix4d& World(int i) {
    std::vector<int> chain;  // `i` and its ancestors not yet done, child first
    for (int n = i; n >= 0 && state_[n] != 2; n = parent_[n]) {
      if (state_[n] == 1) reader_.Fail("the node hierarchy has a cycle");
      state_[n] = 1;
      chain.push_back(n);
    }
    for (auto it = chain.rbegin(); it != chain.rend(); ++it) {
      const int n = *it;
      world_[n] = parent_[n] >= 0 ? Matrix4d(world_[parent_[n]] * NodeLocal(model_.nodes[n]))
                                  : NodeLocal(model_.nodes[n]);
      state_[n] = 2;
    }
    return world_[i];
  }

 private:
  const tinygltf::Model& model_;
  const GltfReader& reader_;
  std::vector<int> parent_;
  std::vector<Matrix4d> world_;
  std::vector<int> state_;  // 0 todo, 1 in progress, 2 done
};

// Index in the skin's joint list of each node; -1 for nodes that are no joint.
std::vector<int> JointOfNode(const tinygltf::Skin& skin, int node_count, const GltfReader& reader) {
  const int joint_count = static_cast<int>(skin.joints.size());
  std::vector<int> joint_of_node(node_count, -1);
  for (int k = 0; k < joint_count; ++k) {
    const int node = skin.joints[k];
    if (node < 0 || node >= node_count)
      reader.Fail("skin 0: bad joint node " + std::to_string(node));
    joint_of_node[node] = k;
  }
  return joint_of_node;
}

// The skin's inverse bind matrices; identity where the skin has none.
std::vector<Matrix4d> InverseBinds(const tinygltf::Skin& skin,
                                   int joint_count,
                                   const GltfReader& reader) {
  std::vector<Matrix4d> inverse_bind(joint_count, Matrix4d::Identity());
  if (skin.inverseBindMatrices >= 0) {
    const std::vector<double> m =
        reader.Read(skin.inverseBindMatrices, 16, "skin 0 inverseBindMatrices");
    if (m.size() < size_t(16) * joint_count)
      reader.Fail("skin 0: fewer inverse bind matrices than joints");
    for (int k = 0; k < joint_count; ++k) {
      for (int i = 0; i < 16; ++i) inverse_bind[k](i % 4, i / 4) = m[16 * k + i];
    }
  }
  return inverse_bind;
}

// The mesh nodes skin 0 deforms, props left out unless there is nothing else.
std::vector<int> SkinnedNodes(const tinygltf::Model& model, const std::string& file) {
  const int node_count = static_cast<int>(model.nodes.size());
  std::vector<int> skinned_nodes, skinned_props;
  for (int i = 0; i < node_count; ++i) {
    const tinygltf::Node& node = model.nodes[i];
    if (node.skin != 0 || node.mesh < 0) continue;
    const bool prop = IsProp(node.name) || (node.mesh < static_cast<int>(model.meshes.size()) &&
                                            IsProp(model.meshes[node.mesh].name));
    (prop ? skinned_props : skinned_nodes).push_back(i);
  }
  if (skinned_nodes.empty()) skinned_nodes = skinned_props;  // only props: take them
  if (skinned_nodes.empty()) throw InputError(file, "skin", "no mesh node uses skin 0");
  return skinned_nodes;
}

// Appends skin 0's joints to `rig` (name, nearest joint ancestor, bind
// position); returns their bind transforms, skin_world x inverse(inverse bind).
std::vector<Matrix4d> AddGltfJoints(const tinygltf::Model& model,
                                    const tinygltf::Skin& skin,
                                    const GltfNodeTree& nodes,
                                    const std::vector<int>& joint_of_node,
                                    const std::vector<Matrix4d>& inverse_bind,
                                    const Matrix4d& skin_world,
                                    const GltfReader& reader,
                                    Rig& rig) {
  const int joint_count = static_cast<int>(skin.joints.size());
  std::vector<Matrix4d> bind(joint_count);
  for (int k = 0; k < joint_count; ++k) {
    const tinygltf::Node& node = model.nodes[skin.joints[k]];
    rig.joint_name.push_back(node.name.empty() ? "joint" + std::to_string(k) : node.name);
    int p = nodes.Parent(skin.joints[k]);
    while (p >= 0 && joint_of_node[p] < 0) p = nodes.Parent(p);
    rig.joint_parent.push_back(p >= 0 ? joint_of_node[p] : -1);
    if (std::abs(inverse_bind[k].determinant()) < 1e-12)
      reader.Fail("skin 0: singular inverse bind matrix of joint '" + rig.joint_name.back() + "'");
    bind[k] = skin_world * inverse_bind[k].inverse();
    rig.joint_bind.push_back(bind[k].block<3, 1>(0, 3));
  }
  return bind;
}

// Appends a glTF model's meshes to a rig: vertices, albedo, influences and
// triangles; each texture image decoded once.
class GltfMeshAdder {
 public:
  GltfMeshAdder(const tinygltf::Model& model,
                const GltfReader& reader,
                const std::string& file,
                int joint_count,
                Rig& rig)
      : model_(model), reader_(reader), file_(file), joint_count_(joint_count), rig_(rig) {}

  // Appends one mesh; `rigid_joint` >= 0: all its vertices on that joint.
  void AddMesh(int mesh_index, const Matrix4d& transform, int rigid_joint) {
    if (mesh_index < 0 || mesh_index >= static_cast<int>(model_.meshes.size()))
      reader_.Fail("bad mesh index");
    const tinygltf::Mesh& mesh = model_.meshes[mesh_index];
    for (size_t pi = 0; pi < mesh.primitives.size(); ++pi) {
      const tinygltf::Primitive& prim = mesh.primitives[pi];
      const std::string what = "mesh '" + mesh.name + "' primitive " + std::to_string(pi);
      if (prim.mode != TINYGLTF_MODE_TRIANGLES) {
        Log().debug("avatar import: {}: {} is not TRIANGLES (mode {}), skipped", file_, what,
                    prim.mode);
        continue;
      }
      AddPrimitive(prim, what, transform, rigid_joint);
    }
  }

 private:
  // Appends one TRIANGLES primitive, its vertices mapped by `transform`.
  void AddPrimitive(const tinygltf::Primitive& prim,
                    const std::string& what,
                    const Matrix4d& transform,
                    int rigid_joint) {
    const auto pos_it = prim.attributes.find("POSITION");
    if (pos_it == prim.attributes.end()) reader_.Fail(what + ": no POSITION");
    const std::vector<double> pos = reader_.Read(pos_it->second, 3, what + " POSITION");
    const size_t n = pos.size() / 3;
    const uint32_t base = static_cast<uint32_t>(rig_.position.size());
    std::vector<std::vector<std::pair<int, float>>> influence =
        ReadInfluence(prim, what, n, rigid_joint);
    // Colour: baseColorFactor x texture.
    Eigen::Vector3f factor(1, 1, 1);
    const Texture* texture = nullptr;
    std::vector<double> uv;
    ReadBaseColour(prim, what, n, factor, texture, uv);
    for (size_t v = 0; v < n; ++v) {
      rig_.position.push_back(
          Apply(transform, Vector3d(pos[3 * v], pos[3 * v + 1], pos[3 * v + 2])));
      Eigen::Vector3f colour = factor;
      if (!uv.empty()) colour = colour.cwiseProduct(Sample(*texture, uv[2 * v], uv[2 * v + 1]));
      rig_.albedo.push_back(AlbedoOf(colour));
      rig_.influence.push_back(std::move(influence[v]));
    }
    AppendTriangles(prim, what, n, base, transform);
  }

  // Per vertex (rig joint, weight) pairs from JOINTS_n/WEIGHTS_n, or weight 1
  // on `rigid_joint` when it is >= 0.
  std::vector<std::vector<std::pair<int, float>>> ReadInfluence(const tinygltf::Primitive& prim,
                                                                const std::string& what,
                                                                size_t n,
                                                                int rigid_joint) const {
    std::vector<std::vector<std::pair<int, float>>> influence(n);
    if (rigid_joint >= 0) {
      for (auto& inf : influence) inf = {{rigid_joint, 1.0f}};
    } else {
      bool any = false;
      for (int set = 0; set < 4; ++set) {
        const auto j_it = prim.attributes.find("JOINTS_" + std::to_string(set));
        const auto w_it = prim.attributes.find("WEIGHTS_" + std::to_string(set));
        if (j_it == prim.attributes.end() || w_it == prim.attributes.end()) break;
        const std::vector<double> joints =
            reader_.Read(j_it->second, 4, what + " JOINTS_" + std::to_string(set));
        const std::vector<double> weights =
            reader_.Read(w_it->second, 4, what + " WEIGHTS_" + std::to_string(set), true);
        if (joints.size() != 4 * n || weights.size() != 4 * n)
          reader_.Fail(what + ": JOINTS/WEIGHTS count differs from POSITION");
        for (size_t v = 0; v < n; ++v) {
          for (int c = 0; c < 4; ++c) {
            const double w = weights[4 * v + c];
            if (!(w > 0)) continue;
            const double j = joints[4 * v + c];
            if (j < 0 || j >= joint_count_)
              reader_.Fail(what + ": joint index " + std::to_string(int(j)) + " out of range");
            influence[v].push_back({static_cast<int>(j), static_cast<float>(w)});
          }
        }
        any = true;
      }
      if (!any)
        throw InputError(file_, "skin", what + " of the skinned mesh has no JOINTS_0/WEIGHTS_0");
    }
    return influence;
  }

  // The material's baseColorFactor into `factor`, its decoded base-colour
  // texture and the primitive's UVs for it (left empty when unusable).
  void ReadBaseColour(const tinygltf::Primitive& prim,
                      const std::string& what,
                      size_t n,
                      Eigen::Vector3f& factor,
                      const Texture*& texture,
                      std::vector<double>& uv) {
    if (prim.material >= 0 && prim.material < static_cast<int>(model_.materials.size())) {
      const auto& pbr = model_.materials[prim.material].pbrMetallicRoughness;
      if (pbr.baseColorFactor.size() >= 3)
        factor =
            Eigen::Vector3f(pbr.baseColorFactor[0], pbr.baseColorFactor[1], pbr.baseColorFactor[2]);
      texture = TextureOf(pbr.baseColorTexture.index);
      const auto uv_it = prim.attributes.find(
          "TEXCOORD_" + std::to_string(std::max(0, pbr.baseColorTexture.texCoord)));
      if (texture && uv_it != prim.attributes.end()) {
        uv = reader_.Read(uv_it->second, 2, what + " TEXCOORD", true);
        if (uv.size() != 2 * n) uv.clear();
      }
    }
  }

  // Texture `texture_index` decoded (once per image); nullptr when it is
  // missing or does not decode.
  const Texture* TextureOf(int texture_index) {
    if (texture_index < 0 || texture_index >= static_cast<int>(model_.textures.size()))
      return nullptr;
    const int source = model_.textures[texture_index].source;
    if (source < 0 || source >= static_cast<int>(model_.images.size())) return nullptr;
    auto it = textures_.find(source);
    if (it == textures_.end()) {
      Texture t = MakeTexture(model_.images[source]);
      it = textures_.emplace(source, std::move(t)).first;
    }
    return it->second.empty() ? nullptr : &it->second;
  }

  // Appends the primitive's triangles (without indices: its vertices three at
  // a time), offset by `base`, the winding reversed by a mirroring `transform`.
  void AppendTriangles(const tinygltf::Primitive& prim,
                       const std::string& what,
                       size_t n,
                       uint32_t base,
                       const Matrix4d& transform) {
    std::vector<double> idx;
    if (prim.indices >= 0) {
      idx = reader_.Read(prim.indices, 1, what + " indices");
      if (idx.size() % 3) reader_.Fail(what + ": index count is not a multiple of 3");
    } else {
      for (size_t i = 0; i < n - n % 3; ++i) idx.push_back(static_cast<double>(i));
    }
    // A mirroring transform reverses the winding (glTF 3.7.4).
    const bool flip = transform.block<3, 3>(0, 0).determinant() < 0;
    for (size_t t = 0; t < idx.size(); t += 3) {
      for (int k : {0, flip ? 2 : 1, flip ? 1 : 2}) {
        const double i = idx[t + k];
        if (i < 0 || i >= n) reader_.Fail(what + ": vertex index out of range");
        rig_.indices.push_back(base + static_cast<uint32_t>(i));
      }
    }
  }

  const tinygltf::Model& model_;
  const GltfReader& reader_;
  const std::string& file_;
  const int joint_count_;
  Rig& rig_;
  std::map<int, Texture> textures_;
};

// Appends the rigid meshes hung under a joint (weight 1 on it, placed by the
// joint's bind transform); props are left out.
void AddRigidGltfMeshes(const tinygltf::Model& model,
                        GltfNodeTree& nodes,
                        const std::vector<int>& joint_of_node,
                        const std::vector<Matrix4d>& bind,
                        const std::string& file,
                        const Rig& rig,
                        GltfMeshAdder& meshes) {
  const int node_count = static_cast<int>(model.nodes.size());
  for (int i = 0; i < node_count; ++i) {
    const tinygltf::Node& node = model.nodes[i];
    if (node.mesh < 0 || node.skin >= 0) continue;
    bool prop = IsProp(node.name) || (node.mesh < static_cast<int>(model.meshes.size()) &&
                                      IsProp(model.meshes[node.mesh].name));
    int a = nodes.Parent(i);
    while (a >= 0 && joint_of_node[a] < 0) {
      prop = prop || IsProp(model.nodes[a].name);
      a = nodes.Parent(a);
    }
    if (a < 0) continue;
    const int joint = joint_of_node[a];
    if (prop || IsProp(rig.joint_name[joint])) {
      Log().debug("avatar import: {}: prop mesh '{}' on '{}' left out", file, node.name,
                  rig.joint_name[joint]);
      continue;
    }
    meshes.AddMesh(node.mesh, Matrix4d(bind[joint] * nodes.World(a).inverse() * nodes.World(i)),
                   joint);
  }
}

}  // namespace

Rig LoadGltf(const fs::path& path) {
  const std::string file = path.string();
  tinygltf::Model model;
  ReadGltfModel(path, file, model);

  const GltfReader reader(model, file);
  const int node_count = static_cast<int>(model.nodes.size());
  if (model.skins.empty())
    throw InputError(file, "skin", "no skin: the file has no rigged (skinned) mesh");
  const tinygltf::Skin& skin = model.skins[0];
  if (skin.joints.empty()) throw InputError(file, "skin", "skin 0 has no joints");
  GltfNodeTree nodes(model, reader, node_count);

  Rig rig;
  rig.unit_scale = 1.0;
  rig.unit_known = true;
  rig.format = "glTF";
  const int joint_count = static_cast<int>(skin.joints.size());
  const std::vector<int> joint_of_node = JointOfNode(skin, node_count, reader);
  const std::vector<Matrix4d> inverse_bind = InverseBinds(skin, joint_count, reader);
  const std::vector<int> skinned_nodes = SkinnedNodes(model, file);
  const Matrix4d skin_world = nodes.World(skinned_nodes[0]);
  const std::vector<Matrix4d> bind =
      AddGltfJoints(model, skin, nodes, joint_of_node, inverse_bind, skin_world, reader, rig);

  GltfMeshAdder meshes(model, reader, file, joint_count, rig);
  for (int node : skinned_nodes) meshes.AddMesh(model.nodes[node].mesh, nodes.World(node), -1);
  AddRigidGltfMeshes(model, nodes, joint_of_node, bind, file, rig, meshes);
  return rig;
}

}  // namespace irbench::import_internal
