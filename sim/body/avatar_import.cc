#include "sim/body/avatar_import.h"

// tinygltf: the Debian shared library (TinyGLTF::TinyGLTF, built with stb and
// nlohmann json), as gltf_export.cc uses it; no TINYGLTF_IMPLEMENTATION here.
// Its stb decoder (tinygltf::LoadImageData) also decodes assimp's textures.
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <tiny_gltf.h>

#include <algorithm>
#include <assimp/Importer.hpp>
#include <cctype>
#include <cmath>
#include <cstring>
#include <fstream>
#include <functional>
#include <limits>
#include <set>
#include <unordered_map>

#include "common/error.h"
#include "common/logging.h"

// How an import works (ImportRiggedAvatar):
//
// 1. Load. glTF: skin 0; every node whose skin is 0 contributes its mesh
//    (TRIANGLES primitives; JOINTS_n/WEIGHTS_n of any component type). Vertices
//    are mesh-space positions mapped by the mesh node's world transform W; joint
//    j's bind transform is W * inverse(inverseBindMatrices[j]) (W of the first
//    skinned node). Assimp: aiBone::mOffsetMatrix is the inverse bind, vertices
//    are mapped by their node's world transform. Rigid meshes hung under a joint
//    (the Wizard's face and shoulder pads) are included with weight 1 on that
//    joint, placed by the joint's bind transform; props are left out (a node,
//    mesh or attachment joint named like weapon, staff, sword, shield, prop,
//    gun, tool; skinned meshes too, unless there is nothing else).
// 2. Map the rig's joints to the canonical ones by name (MapRigJoints): every
//    table is tried and the one mapping the most joints wins. Spine and chest
//    need not exist (they are interpolated), clavicles are optional (placed 20%
//    of the way from the neck to the shoulder), everything else is required.
// 3. Frame: up is the file axis nearest to pelvis -> head (or the option), then
//    a turn about up puts the right shoulder and hip at +x, which makes the
//    character face +y. The feet verify the sides: when the ankle-weighted
//    vertices (the feet) point backwards, the rig's left/right names are the
//    character's right/left and are swapped (with a warning).
// 4. Scale: the option, else glTF metres, FBX UnitScaleFactor (cm per unit),
//    Collada metres (assimp applies the unit); with no unit, centimetres when
//    the height in metres is outside 1.0..2.3 m and its hundredth is inside.
// 5. Weights: each rig joint becomes its mapped canonical joint, else that of
//    its nearest mapped ancestor, else the pelvis (roots above the pelvis, IK
//    helpers); per vertex summed per canonical joint, the 4 largest kept and
//    renormalised to 1.
// 6. Re-pose to the canonical T-pose, world rotations in skeleton order, each
//    the smallest rotation on top of its parent's (so the rig's twist stays):
//    pelvis -> chest, spine -> chest, chest -> neck, neck -> head along +z;
//    shoulder -> elbow, elbow -> wrist along +x (right) / -x (left); hip ->
//    knee, knee -> ankle along -z. The head and the ankles keep the file's
//    orientation (the face keeps looking ahead when a leaning neck is
//    straightened, the feet stay flat on the floor), clavicles the chest's
//    rotation, wrists (hands, fingers) the elbow's. The mesh follows by linear
//    blend skinning with the collapsed weights; the skeleton's bind positions
//    are the re-posed joints. Then the lowest vertex goes to z = 0 and the
//    pelvis over the origin.
// 7. Markers: "head" = centroid of the head-dominated vertices, but not higher
//    than halfway from the head joint to the top of those vertices; hand tips =
//    (+-L, 0, 0) in the wrist frame, L the largest extent along the forearm
//    direction of the hand vertices (wrist-dominated, or elbow-dominated beyond
//    the wrist). Body radii (truth_radius, how deep the point lies under the
//    surface the cameras see): the median distance to the re-posed mesh along
//    16 rays across the body segment from the point (waist, neck, hip, knee,
//    ankle: horizontal; shoulder, elbow, wrist: in the y-z plane; hand tip:
//    from 1.5% of the height behind the tip), for the head along 64 rays in
//    all directions from the head marker; both sides averaged. A median is
//    robust to the rays that run along the body (shoulder -> torso, hip ->
//    other leg, head -> neck) and independent of the tessellation. When most
//    rays miss (a point outside the mesh) the tube avatar's fraction of the
//    height is used.
// 8. Appearance: albedo = 0.8 x Rec. 709 luminance of the linear base colour:
//    the material's baseColorFactor (assimp: base or diffuse colour) times the
//    base-colour texture sampled bilinearly at the vertex's UV (sRGB decoded,
//    by tinygltf's stb decoder) when it decodes; emissive 0. Normals are
//    area-weighted over the re-posed mesh, welded by position (smooth across
//    UV seams).

namespace irbench {
namespace {

namespace fs = std::filesystem;
using Eigen::Matrix3d;
using Eigen::Matrix4d;
using Eigen::Vector3d;

// ---------------------------------------------------------------------------
// Joint-name tables.

std::string Lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

bool StartsWith(const std::string& s, const std::string& prefix) {
  return s.size() > prefix.size() && s.compare(0, prefix.size(), prefix) == 0;
}

// Lower case, namespace ("mixamorig:", "Character1:") and common prefixes
// stripped, '.', '-' and ' ' as '_'.
std::string NormaliseJointName(const std::string& name) {
  std::string s = Lower(name);
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

bool IsLeft(int joint) {
  return std::string(JointName(joint)).rfind("left_", 0) == 0;
}

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

bool IsRequired(int joint) {
  return joint != kSpine && joint != kChest && joint != kRightClavicle && joint != kLeftClavicle;
}

std::string JoinNames(const std::vector<std::string>& names, size_t limit = 60) {
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
        if (Lower(name) == Lower(rig) || NormaliseJointName(name) == NormaliseJointName(rig)) {
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

// ---------------------------------------------------------------------------
// The loaded rig, in the file's world frame and units.

struct Texture {
  int width = 0, height = 0;
  std::vector<Eigen::Vector3f> linear;  // linear RGB, row 0 at the top
  bool empty() const { return linear.empty(); }
};

struct Rig {
  std::vector<std::string> joint_name;
  std::vector<int> joint_parent;     // nearest ancestor that is a joint; -1
  std::vector<Vector3d> joint_bind;  // bind position
  std::vector<Vector3d> position;    // vertices, bind pose
  std::vector<float> albedo;         // per vertex
  std::vector<uint32_t> indices;
  std::vector<std::vector<std::pair<int, float>>> influence;  // rig joint, weight
  double unit_scale = 1.0;                                    // metres per unit
  bool unit_known = false;
  std::string format;
};

bool IsProp(const std::string& name) {
  const std::string s = Lower(name);
  for (const char* word : {"weapon", "staff", "sword", "shield", "prop", "gun", "tool"}) {
    if (s.find(word) != std::string::npos) return true;
  }
  return false;
}

float SrgbToLinear(float c) {
  return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
}

// A decoded tinygltf image (1..4 components, 8 or 16 bits, sRGB) -> linear RGB.
Texture MakeTexture(const tinygltf::Image& image) {
  Texture t;
  const int comp = image.component, bytes = image.bits / 8;
  if (image.width < 1 || image.height < 1 || comp < 1 || comp > 4 || (bytes != 1 && bytes != 2) ||
      image.image.size() < static_cast<size_t>(image.width) * image.height * comp * bytes) {
    return t;
  }
  t.width = image.width;
  t.height = image.height;
  t.linear.resize(static_cast<size_t>(t.width) * t.height);
  std::vector<float> lut(bytes == 1 ? 256 : 65536);
  for (size_t i = 0; i < lut.size(); ++i)
    lut[i] = SrgbToLinear(static_cast<float>(i) / (lut.size() - 1));
  for (size_t p = 0; p < t.linear.size(); ++p) {
    auto channel = [&](int c) {
      const unsigned char* q = &image.image[(p * comp + c) * bytes];
      return bytes == 1 ? lut[*q] : lut[q[0] | (q[1] << 8)];
    };
    const float r = channel(0);
    t.linear[p] = comp >= 3 ? Eigen::Vector3f(r, channel(1), channel(2)) : Eigen::Vector3f(r, r, r);
  }
  return t;
}

// Decodes PNG/JPEG bytes with tinygltf's stb decoder; empty when it cannot.
Texture DecodeTexture(const unsigned char* bytes, int size) {
  tinygltf::Image image;
  std::string err, warn;
  if (size <= 0 || !tinygltf::LoadImageData(&image, 0, &err, &warn, 0, 0, bytes, size, nullptr))
    return {};
  return MakeTexture(image);
}

// Bilinear, repeating; (u, v) with v = 0 at the top row.
Eigen::Vector3f Sample(const Texture& t, double u, double v) {
  const int w = t.width, h = t.height;
  const double x = (u - std::floor(u)) * w - 0.5, y = (v - std::floor(v)) * h - 0.5;
  const int x0 = static_cast<int>(std::floor(x)), y0 = static_cast<int>(std::floor(y));
  const float fx = static_cast<float>(x - x0), fy = static_cast<float>(y - y0);
  auto at = [&](int xi, int yi) {
    return t.linear[static_cast<size_t>(((yi % h) + h) % h) * w + ((xi % w) + w) % w];
  };
  return (1 - fy) * ((1 - fx) * at(x0, y0) + fx * at(x0 + 1, y0)) +
         fy * ((1 - fx) * at(x0, y0 + 1) + fx * at(x0 + 1, y0 + 1));
}

float AlbedoOf(const Eigen::Vector3f& linear_rgb) {
  const float y = 0.2126f * linear_rgb.x() + 0.7152f * linear_rgb.y() + 0.0722f * linear_rgb.z();
  return std::clamp(0.8f * y, 0.0f, 1.0f);
}

// ---------------------------------------------------------------------------
// glTF.

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
    std::vector<double> out(a.count * static_cast<size_t>(n), 0.0);
    if (a.bufferView < 0) return out;  // all zeros by the specification
    if (a.bufferView >= static_cast<int>(m_.bufferViews.size())) Fail(what + ": bad buffer view");
    const tinygltf::BufferView& view = m_.bufferViews[a.bufferView];
    if (view.buffer < 0 || view.buffer >= static_cast<int>(m_.buffers.size()))
      Fail(what + ": bad buffer");
    const std::vector<unsigned char>& data = m_.buffers[view.buffer].data;
    const int stride = a.ByteStride(view);
    if (stride <= 0) Fail(what + ": bad byte stride");
    const size_t begin = view.byteOffset + a.byteOffset;
    const size_t end_needed =
        a.count == 0 ? begin
                     : begin + static_cast<size_t>(stride) * (a.count - 1) + size_t(n) * size;
    if (end_needed > view.byteOffset + view.byteLength || end_needed > data.size()) {
      Fail(what + ": accessor " + std::to_string(index) + " runs past its buffer");
    }
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

Vector3d Apply(const Matrix4d& m, const Vector3d& p) {
  return m.block<3, 3>(0, 0) * p + m.block<3, 1>(0, 3);
}

Rig LoadGltf(const fs::path& path) {
  const std::string file = path.string();
  std::string magic(4, '\0');
  {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw InputError(file, "file", "cannot open");
    in.read(magic.data(), 4);
  }
  tinygltf::Model model;
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

  const GltfReader reader(model, file);
  const int node_count = static_cast<int>(model.nodes.size());
  if (model.skins.empty())
    throw InputError(file, "skin", "no skin: the file has no rigged (skinned) mesh");
  const tinygltf::Skin& skin = model.skins[0];
  if (skin.joints.empty()) throw InputError(file, "skin", "skin 0 has no joints");

  std::vector<int> parent(node_count, -1);
  for (int i = 0; i < node_count; ++i) {
    for (int c : model.nodes[i].children) {
      if (c < 0 || c >= node_count || parent[c] >= 0 || c == i)
        reader.Fail("node " + std::to_string(i) + ": bad child " + std::to_string(c));
      parent[c] = i;
    }
  }
  std::vector<Matrix4d> world(node_count);
  std::vector<int> state(node_count, 0);  // 0 todo, 1 in progress, 2 done
  std::function<const Matrix4d&(int)> world_of = [&](int i) -> const Matrix4d& {
    if (state[i] == 1) reader.Fail("the node hierarchy has a cycle");
    if (state[i] == 0) {
      state[i] = 1;
      world[i] = parent[i] >= 0 ? Matrix4d(world_of(parent[i]) * NodeLocal(model.nodes[i]))
                                : NodeLocal(model.nodes[i]);
      state[i] = 2;
    }
    return world[i];
  };

  Rig rig;
  rig.unit_scale = 1.0;
  rig.unit_known = true;
  rig.format = "glTF";
  const int joint_count = static_cast<int>(skin.joints.size());
  std::vector<int> joint_of_node(node_count, -1);
  for (int k = 0; k < joint_count; ++k) {
    const int node = skin.joints[k];
    if (node < 0 || node >= node_count)
      reader.Fail("skin 0: bad joint node " + std::to_string(node));
    joint_of_node[node] = k;
  }
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
  const Matrix4d skin_world = world_of(skinned_nodes[0]);

  std::vector<Matrix4d> bind(joint_count);
  for (int k = 0; k < joint_count; ++k) {
    const tinygltf::Node& node = model.nodes[skin.joints[k]];
    rig.joint_name.push_back(node.name.empty() ? "joint" + std::to_string(k) : node.name);
    int p = parent[skin.joints[k]];
    while (p >= 0 && joint_of_node[p] < 0) p = parent[p];
    rig.joint_parent.push_back(p >= 0 ? joint_of_node[p] : -1);
    if (std::abs(inverse_bind[k].determinant()) < 1e-12)
      reader.Fail("skin 0: singular inverse bind matrix of joint '" + rig.joint_name.back() + "'");
    bind[k] = skin_world * inverse_bind[k].inverse();
    rig.joint_bind.push_back(bind[k].block<3, 1>(0, 3));
  }

  // Textures decoded once per image.
  std::map<int, Texture> textures;
  auto texture_of = [&](int texture_index) -> const Texture* {
    if (texture_index < 0 || texture_index >= static_cast<int>(model.textures.size()))
      return nullptr;
    const int source = model.textures[texture_index].source;
    if (source < 0 || source >= static_cast<int>(model.images.size())) return nullptr;
    auto it = textures.find(source);
    if (it == textures.end()) {
      Texture t = MakeTexture(model.images[source]);
      it = textures.emplace(source, std::move(t)).first;
    }
    return it->second.empty() ? nullptr : &it->second;
  };

  // Appends one mesh; `rigid_joint` >= 0: all its vertices on that joint.
  auto add_mesh = [&](int mesh_index, const Matrix4d& transform, int rigid_joint) {
    if (mesh_index < 0 || mesh_index >= static_cast<int>(model.meshes.size()))
      reader.Fail("bad mesh index");
    const tinygltf::Mesh& mesh = model.meshes[mesh_index];
    for (size_t pi = 0; pi < mesh.primitives.size(); ++pi) {
      const tinygltf::Primitive& prim = mesh.primitives[pi];
      const std::string what = "mesh '" + mesh.name + "' primitive " + std::to_string(pi);
      if (prim.mode != TINYGLTF_MODE_TRIANGLES) {
        Log().debug("avatar import: {}: {} is not TRIANGLES (mode {}), skipped", file, what,
                    prim.mode);
        continue;
      }
      const auto pos_it = prim.attributes.find("POSITION");
      if (pos_it == prim.attributes.end()) reader.Fail(what + ": no POSITION");
      const std::vector<double> pos = reader.Read(pos_it->second, 3, what + " POSITION");
      const size_t n = pos.size() / 3;
      const uint32_t base = static_cast<uint32_t>(rig.position.size());
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
              reader.Read(j_it->second, 4, what + " JOINTS_" + std::to_string(set));
          const std::vector<double> weights =
              reader.Read(w_it->second, 4, what + " WEIGHTS_" + std::to_string(set), true);
          if (joints.size() != 4 * n || weights.size() != 4 * n)
            reader.Fail(what + ": JOINTS/WEIGHTS count differs from POSITION");
          for (size_t v = 0; v < n; ++v) {
            for (int c = 0; c < 4; ++c) {
              const double w = weights[4 * v + c];
              if (!(w > 0)) continue;
              const double j = joints[4 * v + c];
              if (j < 0 || j >= joint_count)
                reader.Fail(what + ": joint index " + std::to_string(int(j)) + " out of range");
              influence[v].push_back({static_cast<int>(j), static_cast<float>(w)});
            }
          }
          any = true;
        }
        if (!any)
          throw InputError(file, "skin", what + " of the skinned mesh has no JOINTS_0/WEIGHTS_0");
      }
      // Colour: baseColorFactor x texture.
      Eigen::Vector3f factor(1, 1, 1);
      const Texture* texture = nullptr;
      std::vector<double> uv;
      if (prim.material >= 0 && prim.material < static_cast<int>(model.materials.size())) {
        const auto& pbr = model.materials[prim.material].pbrMetallicRoughness;
        if (pbr.baseColorFactor.size() >= 3)
          factor = Eigen::Vector3f(pbr.baseColorFactor[0], pbr.baseColorFactor[1],
                                   pbr.baseColorFactor[2]);
        texture = texture_of(pbr.baseColorTexture.index);
        const auto uv_it = prim.attributes.find(
            "TEXCOORD_" + std::to_string(std::max(0, pbr.baseColorTexture.texCoord)));
        if (texture && uv_it != prim.attributes.end()) {
          uv = reader.Read(uv_it->second, 2, what + " TEXCOORD", true);
          if (uv.size() != 2 * n) uv.clear();
        }
      }
      for (size_t v = 0; v < n; ++v) {
        rig.position.push_back(
            Apply(transform, Vector3d(pos[3 * v], pos[3 * v + 1], pos[3 * v + 2])));
        Eigen::Vector3f colour = factor;
        if (!uv.empty()) colour = colour.cwiseProduct(Sample(*texture, uv[2 * v], uv[2 * v + 1]));
        rig.albedo.push_back(AlbedoOf(colour));
        rig.influence.push_back(std::move(influence[v]));
      }
      std::vector<double> idx;
      if (prim.indices >= 0) {
        idx = reader.Read(prim.indices, 1, what + " indices");
        if (idx.size() % 3) reader.Fail(what + ": index count is not a multiple of 3");
      } else {
        for (size_t i = 0; i < n - n % 3; ++i) idx.push_back(static_cast<double>(i));
      }
      // A mirroring transform reverses the winding (glTF 3.7.4).
      const bool flip = transform.block<3, 3>(0, 0).determinant() < 0;
      for (size_t t = 0; t < idx.size(); t += 3) {
        for (int k : {0, flip ? 2 : 1, flip ? 1 : 2}) {
          const double i = idx[t + k];
          if (i < 0 || i >= n) reader.Fail(what + ": vertex index out of range");
          rig.indices.push_back(base + static_cast<uint32_t>(i));
        }
      }
    }
  };

  for (int node : skinned_nodes) add_mesh(model.nodes[node].mesh, world_of(node), -1);
  // Rigid meshes hung under a joint.
  for (int i = 0; i < node_count; ++i) {
    const tinygltf::Node& node = model.nodes[i];
    if (node.mesh < 0 || node.skin >= 0) continue;
    bool prop = IsProp(node.name) || (node.mesh < static_cast<int>(model.meshes.size()) &&
                                      IsProp(model.meshes[node.mesh].name));
    int a = parent[i];
    while (a >= 0 && joint_of_node[a] < 0) {
      prop = prop || IsProp(model.nodes[a].name);
      a = parent[a];
    }
    if (a < 0) continue;
    const int joint = joint_of_node[a];
    if (prop || IsProp(rig.joint_name[joint])) {
      Log().debug("avatar import: {}: prop mesh '{}' on '{}' left out", file, node.name,
                  rig.joint_name[joint]);
      continue;
    }
    add_mesh(node.mesh, Matrix4d(bind[joint] * world_of(a).inverse() * world_of(i)), joint);
  }
  return rig;
}

// ---------------------------------------------------------------------------
// Assimp.

Matrix4d ToEigen(const aiMatrix4x4& m) {
  Matrix4d out;
  out << m.a1, m.a2, m.a3, m.a4, m.b1, m.b2, m.b3, m.b4, m.c1, m.c2, m.c3, m.c4, m.d1, m.d2, m.d3,
      m.d4;
  return out;
}

Matrix4d NodeWorld(const aiNode* node) {
  Matrix4d m = Matrix4d::Identity();
  for (const aiNode* n = node; n != nullptr; n = n->mParent) m = ToEigen(n->mTransformation) * m;
  return m;
}

Rig LoadAssimp(const fs::path& path) {
  const std::string file = path.string();
  Assimp::Importer importer;
  const aiScene* scene = importer.ReadFile(
      file, aiProcess_Triangulate | aiProcess_LimitBoneWeights | aiProcess_JoinIdenticalVertices);
  if (scene == nullptr || scene->mRootNode == nullptr) {
    throw InputError(file, "file",
                     std::string("not a readable model: ") + importer.GetErrorString());
  }
  std::string ext = Lower(path.extension().string());
  Rig rig;
  rig.format = ext;
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

  // Mesh instances: (mesh, node).
  std::vector<std::pair<unsigned, const aiNode*>> instances;
  std::function<void(const aiNode*)> walk = [&](const aiNode* n) {
    for (unsigned i = 0; i < n->mNumMeshes; ++i) instances.push_back({n->mMeshes[i], n});
    for (unsigned i = 0; i < n->mNumChildren; ++i) walk(n->mChildren[i]);
  };
  walk(scene->mRootNode);
  if (scene->mNumMeshes == 0) throw InputError(file, "skin", "no mesh in the file");

  // Bones: bind world = mesh node world x inverse(offset), first seen wins.
  std::map<std::string, Matrix4d> bone_bind;
  std::vector<const aiNode*> bone_nodes;
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

  // Joints: the bones and the other plain nodes under their common ancestor.
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
  std::set<const aiNode*> is_bone(bone_nodes.begin(), bone_nodes.end());
  std::map<const aiNode*, int> joint_of;
  std::vector<const aiNode*> joints;
  std::function<void(const aiNode*)> collect = [&](const aiNode* n) {
    const std::string name = n->mName.C_Str();
    if (is_bone.count(n) ||
        (n->mNumMeshes == 0 && name.find("$AssimpFbx$") == std::string::npos && !name.empty())) {
      joint_of[n] = static_cast<int>(joints.size());
      joints.push_back(n);
    }
    for (unsigned i = 0; i < n->mNumChildren; ++i) collect(n->mChildren[i]);
  };
  collect(top);
  for (const aiNode* b : bone_nodes) {
    if (!joint_of.count(b)) {  // cannot happen (all under `top`), but keep every bone
      joint_of[b] = static_cast<int>(joints.size());
      joints.push_back(b);
    }
  }
  // Bind transforms: bones from their offsets; other joints move rigidly with
  // their nearest bone ancestor, else keep their node transform.
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

  // Materials: colour and texture.
  std::map<std::string, Texture> textures;
  auto texture_of = [&](const aiMaterial* material) -> const Texture* {
    aiString tex_path;
    if (material->GetTexture(aiTextureType_BASE_COLOR, 0, &tex_path) != AI_SUCCESS &&
        material->GetTexture(aiTextureType_DIFFUSE, 0, &tex_path) != AI_SUCCESS) {
      return nullptr;
    }
    const std::string key = tex_path.C_Str();
    auto it = textures.find(key);
    if (it == textures.end()) {
      Texture t;
      if (const aiTexture* embedded = scene->GetEmbeddedTexture(key.c_str())) {
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
        std::ifstream in(path.parent_path() / key, std::ios::binary);
        const std::string bytes((std::istreambuf_iterator<char>(in)),
                                std::istreambuf_iterator<char>());
        t = DecodeTexture(reinterpret_cast<const unsigned char*>(bytes.data()),
                          static_cast<int>(bytes.size()));
      }
      it = textures.emplace(key, std::move(t)).first;
    }
    return it->second.empty() ? nullptr : &it->second;
  };

  auto add_mesh = [&](const aiMesh* mesh, const Matrix4d& transform, int rigid_joint) {
    const uint32_t base = static_cast<uint32_t>(rig.position.size());
    const size_t n = mesh->mNumVertices;
    std::vector<std::vector<std::pair<int, float>>> influence(n);
    if (rigid_joint >= 0) {
      for (auto& inf : influence) inf = {{rigid_joint, 1.0f}};
    } else {
      for (unsigned b = 0; b < mesh->mNumBones; ++b) {
        const aiBone* bone = mesh->mBones[b];
        const int joint = joint_of.at(scene->mRootNode->FindNode(bone->mName));
        for (unsigned w = 0; w < bone->mNumWeights; ++w) {
          const aiVertexWeight& vw = bone->mWeights[w];
          if (vw.mVertexId < n && vw.mWeight > 0)
            influence[vw.mVertexId].push_back({joint, vw.mWeight});
        }
      }
    }
    Eigen::Vector3f factor(1, 1, 1);
    const Texture* texture = nullptr;
    if (mesh->mMaterialIndex < scene->mNumMaterials) {
      const aiMaterial* material = scene->mMaterials[mesh->mMaterialIndex];
      aiColor4D c;
      if (material->Get(AI_MATKEY_BASE_COLOR, c) == AI_SUCCESS ||
          material->Get(AI_MATKEY_COLOR_DIFFUSE, c) == AI_SUCCESS) {
        factor = Eigen::Vector3f(c.r, c.g, c.b);
      }
      if (mesh->mTextureCoords[0] != nullptr) texture = texture_of(material);
    }
    for (size_t v = 0; v < n; ++v) {
      const aiVector3D& p = mesh->mVertices[v];
      rig.position.push_back(Apply(transform, Vector3d(p.x, p.y, p.z)));
      Eigen::Vector3f colour = factor;
      if (texture) {
        const aiVector3D& t = mesh->mTextureCoords[0][v];
        colour = colour.cwiseProduct(Sample(*texture, t.x, 1.0 - t.y));  // assimp's v points up
      }
      rig.albedo.push_back(AlbedoOf(colour));
      rig.influence.push_back(std::move(influence[v]));
    }
    const bool flip =
        transform.block<3, 3>(0, 0).determinant() < 0;  // mirrored: reverse the winding
    for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
      const aiFace& face = mesh->mFaces[f];
      if (face.mNumIndices != 3) continue;  // points and lines
      for (int k : {0, flip ? 2 : 1, flip ? 1 : 2}) {
        if (face.mIndices[k] >= n) throw InputError(file, "file", "vertex index out of range");
        rig.indices.push_back(base + face.mIndices[k]);
      }
    }
  };
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
        add_mesh(mesh, NodeWorld(node), -1);
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
    add_mesh(mesh, Matrix4d(bind[joint] * NodeWorld(a).inverse() * NodeWorld(node)), joint);
  }
  return rig;
}

// ---------------------------------------------------------------------------
// Canonical avatar from a rig.

std::string JoinCanonical(const std::vector<int>& joints) {
  std::vector<std::string> names;
  for (int j : joints) names.push_back(JointName(j));
  return JoinNames(names);
}

int Mirror(int joint) {
  static const int kMirror[kJointCount] = {kPelvis,     kSpine,         kChest,         kNeck,
                                           kHead,       kLeftClavicle,  kLeftShoulder,  kLeftElbow,
                                           kLeftWrist,  kRightClavicle, kRightShoulder, kRightElbow,
                                           kRightWrist, kLeftHip,       kLeftKnee,      kLeftAnkle,
                                           kRightHip,   kRightKnee,     kRightAnkle};
  return kMirror[joint];
}

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// Distance along the unit ray (o, d) to the nearest triangle; infinity if none.
double RayHit(const std::vector<Vector3d>& verts,
              const std::vector<uint32_t>& indices,
              const Vector3d& o,
              const Vector3d& d) {
  double best = std::numeric_limits<double>::infinity();
  for (size_t t = 0; t + 2 < indices.size(); t += 3) {  // Moller-Trumbore
    const Vector3d& a = verts[indices[t]];
    const Vector3d e1 = verts[indices[t + 1]] - a, e2 = verts[indices[t + 2]] - a;
    const Vector3d p = d.cross(e2);
    const double det = e1.dot(p);
    if (std::abs(det) < 1e-14) continue;
    const Vector3d s = o - a;
    const double u = s.dot(p) / det;
    if (u < 0 || u > 1) continue;
    const Vector3d qv = s.cross(e1);
    const double v = d.dot(qv) / det;
    if (v < 0 || u + v > 1) continue;
    const double dist = e2.dot(qv) / det;
    if (dist > 1e-9 && dist < best) best = dist;
  }
  return best;
}

Avatar BuildAvatar(const Rig& rig, const fs::path& path, const ImportOptions& options) {
  const std::string file = path.string();
  if (!(options.scale >= 0) || !std::isfinite(options.scale)) {
    throw InputError(file, "scale", "must be > 0 (metres per file unit) or 0 (automatic)");
  }
  if (rig.indices.empty()) throw InputError(file, "skin", "the skinned mesh has no triangles");
  for (const Vector3d& p : rig.position) {
    if (!p.allFinite()) throw InputError(file, "file", "the mesh has non-finite vertex positions");
  }
  for (const Vector3d& p : rig.joint_bind) {
    if (!p.allFinite()) throw InputError(file, "file", "a joint has a non-finite bind position");
  }

  JointMapping mapping = MapJoints(rig.joint_name, options.joint_map, file);
  std::array<int, kJointCount> rig_of;
  rig_of.fill(-1);
  for (const auto& [canonical, rig_name] : mapping.map) {
    const int j = *JointFromName(canonical);
    for (size_t k = 0; k < rig.joint_name.size(); ++k) {
      if (rig.joint_name[k] == rig_name) {
        rig_of[j] = static_cast<int>(k);
        break;
      }
    }
  }
  {
    std::vector<int> arms, torso, legs;
    for (int j :
         {kRightShoulder, kRightElbow, kRightWrist, kLeftShoulder, kLeftElbow, kLeftWrist}) {
      if (rig_of[j] < 0) arms.push_back(j);
    }
    for (int j : {kPelvis, kNeck, kHead}) {
      if (rig_of[j] < 0) torso.push_back(j);
    }
    for (int j : {kRightHip, kRightKnee, kRightAnkle, kLeftHip, kLeftKnee, kLeftAnkle}) {
      if (rig_of[j] < 0) legs.push_back(j);
    }
    std::vector<int> missing = arms;
    missing.insert(missing.end(), torso.begin(), torso.end());
    missing.insert(missing.end(), legs.begin(), legs.end());
    if (!missing.empty()) {
      const std::string what = !arms.empty()    ? "no arm chain"
                               : !torso.empty() ? "no torso chain"
                                                : "no leg chain";
      throw InputError(file, "skin",
                       what + ": cannot map " + JoinCanonical(missing) +
                           " (rig joints: " + JoinNames(rig.joint_name) + "; best table '" +
                           mapping.convention + "'; pass a joint map)");
    }
  }

  // Canonical joint of each rig joint: itself, its nearest mapped ancestor, the pelvis.
  const int rig_joints = static_cast<int>(rig.joint_name.size());
  std::vector<int> canonical_of(rig_joints, -1);
  for (int j = 0; j < kJointCount; ++j) {
    if (rig_of[j] >= 0) canonical_of[rig_of[j]] = j;
  }
  std::vector<int> collapsed(rig_joints, kPelvis);
  for (int k = 0; k < rig_joints; ++k) {
    int a = k;
    for (int guard = 0; a >= 0 && canonical_of[a] < 0 && guard <= rig_joints; ++guard)
      a = rig.joint_parent[a];
    collapsed[k] = a >= 0 && canonical_of[a] >= 0 ? canonical_of[a] : kPelvis;
  }

  // Collapsed weights (before any side swap).
  const size_t n = rig.position.size();
  std::vector<std::array<uint8_t, 4>> bone_index(n);
  std::vector<std::array<float, 4>> bone_weight(n);
  std::vector<int> unweighted;
  for (size_t v = 0; v < n; ++v) {
    std::array<double, kJointCount> sum{};
    for (const auto& [joint, w] : rig.influence[v]) sum[collapsed[joint]] += w;
    std::array<int, kJointCount> order;
    for (int j = 0; j < kJointCount; ++j) order[j] = j;
    std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return sum[a] > sum[b]; });
    double total = 0;
    for (int k = 0; k < 4; ++k) total += sum[order[k]];
    bone_index[v] = {0, 0, 0, 0};
    bone_weight[v] = {0, 0, 0, 0};
    if (!(total > 0)) {
      unweighted.push_back(static_cast<int>(v));
      continue;
    }
    for (int k = 0; k < 4; ++k) {
      bone_index[v][k] = static_cast<uint8_t>(sum[order[k]] > 0 ? order[k] : 0);
      bone_weight[v][k] = static_cast<float>(sum[order[k]] / total);
    }
  }

  // Frame: up axis, facing, scale. Repeated once with the sides swapped when
  // the feet point backwards.
  std::array<Vector3d, kJointCount> p;  // canonical joints, world, before re-posing
  std::vector<Vector3d> verts(n);
  double scale = 0;
  Matrix3d frame = Matrix3d::Identity();
  std::string up_used;
  for (int attempt = 0; attempt < 2; ++attempt) {
    auto rp = [&](int j) { return rig.joint_bind[rig_of[j]]; };
    Matrix3d up_rotation = Matrix3d::Identity();
    if (options.up_axis == "z") {
      up_used = "z";
    } else if (options.up_axis == "y") {
      up_rotation = Eigen::AngleAxisd(M_PI / 2, Vector3d::UnitX()).toRotationMatrix();
      up_used = "y";
    } else if (options.up_axis == "auto" || options.up_axis.empty()) {
      const Vector3d d = rp(kHead) - rp(kPelvis);
      if (d.norm() < 1e-9) throw InputError(file, "skin", "the pelvis and head joints coincide");
      int axis = 0;
      d.cwiseAbs().maxCoeff(&axis);
      Vector3d up = Vector3d::Zero();
      up[axis] = d[axis] > 0 ? 1 : -1;
      up_rotation =
          up.z() < -0.5
              ? Eigen::AngleAxisd(M_PI, Vector3d::UnitX()).toRotationMatrix()
              : Eigen::Quaterniond::FromTwoVectors(up, Vector3d::UnitZ()).toRotationMatrix();
      up_used = std::string(d[axis] > 0 ? "+" : "-") + "xyz"[axis] + " (auto)";
    } else {
      throw InputError(file, "up_axis", "must be auto, y or z, not '" + options.up_axis + "'");
    }
    Vector3d right =
        up_rotation * ((rp(kRightShoulder) - rp(kLeftShoulder)) + (rp(kRightHip) - rp(kLeftHip)));
    right.z() = 0;
    if (right.norm() < 1e-9)
      throw InputError(file, "skin",
                       "cannot tell the facing: the left and right shoulders and hips coincide");
    frame =
        Eigen::AngleAxisd(-std::atan2(right.y(), right.x()), Vector3d::UnitZ()).toRotationMatrix() *
        up_rotation;

    scale = options.scale > 0 ? options.scale : rig.unit_scale;
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (const Vector3d& v : rig.position) {
      const double z = (frame * v).z();
      lo = std::min(lo, z), hi = std::max(hi, z);
    }
    const double height = (hi - lo) * scale;
    if (options.scale == 0 && !rig.unit_known && (height < 1.0 || height > 2.3) &&
        height * 0.01 >= 1.0 && height * 0.01 <= 2.3) {
      Log().info(
          "avatar import: {}: {:.1f} units tall and no unit in the file: reading centimetres", file,
          hi - lo);
      scale *= 0.01;
    }
    for (size_t v = 0; v < n; ++v) verts[v] = scale * (frame * rig.position[v]);
    for (int j = 0; j < kJointCount; ++j) {
      if (rig_of[j] >= 0) p[j] = scale * (frame * rp(j));
    }
    // The feet must point forward (+y); else the rig's sides are mirrored.
    double forward = 0, spread = 0;
    int count = 0;
    for (size_t v = 0; v < n; ++v) {
      const int j = bone_weight[v][0] > 0 ? bone_index[v][0] : -1;
      if (j != kRightAnkle && j != kLeftAnkle) continue;
      const Vector3d d = verts[v] - p[j];
      forward += d.y();
      spread += std::hypot(d.x(), d.y());
      ++count;
    }
    if (attempt == 0 && count >= 8 && forward < -0.25 * spread) {
      Log().warn(
          "avatar import: {}: the feet point backwards: the rig's left/right joint names are the "
          "character's right/left; swapping them",
          file);
      std::array<int, kJointCount> swapped;
      for (int j = 0; j < kJointCount; ++j) swapped[j] = rig_of[Mirror(j)];
      rig_of = swapped;
      for (size_t v = 0; v < n; ++v) {
        for (int k = 0; k < 4; ++k)
          bone_index[v][k] = static_cast<uint8_t>(Mirror(bone_index[v][k]));
      }
      std::map<std::string, std::string> map;
      for (const auto& [canonical, rig_name] : mapping.map)
        map[JointName(Mirror(*JointFromName(canonical)))] = rig_name;
      mapping.map = map;
      continue;
    }
    break;
  }

  // Unmapped spine, chest and clavicles.
  if (rig_of[kSpine] < 0 && rig_of[kChest] < 0) {
    p[kSpine] = p[kPelvis] + 0.25 * (p[kNeck] - p[kPelvis]);
    p[kChest] = p[kPelvis] + 0.63 * (p[kNeck] - p[kPelvis]);
  } else if (rig_of[kSpine] < 0) {
    p[kSpine] = p[kPelvis] + 0.4 * (p[kChest] - p[kPelvis]);
  } else if (rig_of[kChest] < 0) {
    p[kChest] = p[kSpine] + 0.5 * (p[kNeck] - p[kSpine]);
  }
  for (int clav : {kRightClavicle, kLeftClavicle}) {
    if (rig_of[clav] < 0) p[clav] = p[kNeck] + 0.2 * (p[clav + 1] - p[kNeck]);
  }
  // Vertices with no weight at all go with the nearest joint.
  for (int v : unweighted) {
    int best = kPelvis;
    for (int j = 0; j < kJointCount; ++j) {
      if ((verts[v] - p[j]).squaredNorm() < (verts[v] - p[best]).squaredNorm()) best = j;
    }
    bone_index[v] = {static_cast<uint8_t>(best), 0, 0, 0};
    bone_weight[v] = {1, 0, 0, 0};
  }

  // Re-pose into the T-pose.
  std::array<Matrix3d, kJointCount> rot;
  const Vector3d ux = Vector3d::UnitX(), uz = Vector3d::UnitZ();
  auto aim = [&](int j, int child, const Vector3d& target, int parent) {
    const Matrix3d base = parent >= 0 ? rot[parent] : Matrix3d(Matrix3d::Identity());
    const Vector3d bone = base * (p[child] - p[j]);
    if (bone.norm() < 1e-9)
      throw InputError(
          file, "skin",
          std::string("the ") + JointName(j) + " and " + JointName(child) + " joints coincide");
    rot[j] = Eigen::Quaterniond::FromTwoVectors(bone, target).toRotationMatrix() * base;
  };
  aim(kPelvis, kChest, uz, -1);
  aim(kSpine, kChest, uz, kPelvis);
  aim(kChest, kNeck, uz, kSpine);
  aim(kNeck, kHead, uz, kChest);
  rot[kHead] = Matrix3d::Identity();
  for (int side : {+1, -1}) {
    const int clav = side > 0 ? kRightClavicle : kLeftClavicle;
    rot[clav] = rot[kChest];
    aim(clav + 1, clav + 2, side * ux, clav);
    aim(clav + 2, clav + 3, side * ux, clav + 1);
    rot[clav + 3] = rot[clav + 2];
    const int hip = side > 0 ? kRightHip : kLeftHip;
    aim(hip, hip + 1, -uz, kPelvis);
    aim(hip + 1, hip + 2, -uz, hip);
    rot[hip + 2] = Matrix3d::Identity();
  }
  std::array<Vector3d, kJointCount> q;
  for (int j = 0; j < kJointCount; ++j) {
    const int parent = JointParent(j);
    q[j] = parent < 0 ? p[j] : Vector3d(q[parent] + rot[parent] * (p[j] - p[parent]));
  }
  for (size_t v = 0; v < n; ++v) {
    Vector3d out = Vector3d::Zero();
    for (int k = 0; k < 4; ++k) {
      const float w = bone_weight[v][k];
      if (w == 0) continue;
      const int j = bone_index[v][k];
      out += w * (q[j] + rot[j] * (verts[v] - p[j]));
    }
    verts[v] = out;
  }
  // Feet on the floor, pelvis over the origin.
  double floor_z = std::numeric_limits<double>::infinity(), top_z = -floor_z;
  for (const Vector3d& v : verts)
    floor_z = std::min(floor_z, v.z()), top_z = std::max(top_z, v.z());
  const Vector3d shift(-q[kPelvis].x(), -q[kPelvis].y(), -floor_z);
  for (Vector3d& v : verts) v += shift;
  for (Vector3d& j : q) j += shift;
  const double h = top_z - floor_z;
  if (!(h >= 1.0 && h <= 2.3)) {
    char buf[256];
    std::snprintf(buf, sizeof buf,
                  "the imported body is %.3f m tall at %.4g m per file unit; expected 1.0..2.3 m "
                  "(give \"scale\" in metres per file unit in an avatar file of kind \"mesh\", see "
                  "docs/avatars.md)",
                  h, scale);
    throw InputError(file, "height", buf);
  }

  Avatar avatar;
  avatar.params.name = options.name.empty() ? path.stem().string() : options.name;
  avatar.params.kind = "mesh";
  avatar.params.height_m = h;
  avatar.params.build = 1.0;
  for (int j = 0; j < kJointCount; ++j) avatar.skeleton.bind_position[j] = q[j];
  avatar.indices = rig.indices;
  avatar.bone_index = bone_index;
  avatar.bone_weight = bone_weight;
  avatar.bind_vertices.resize(n);
  for (size_t v = 0; v < n; ++v) {
    MeshVertex& mv = avatar.bind_vertices[v];
    mv.position = verts[v].cast<float>();
    mv.albedo = rig.albedo[v];
    mv.emissive = 0.0f;
  }

  // Normals: area-weighted, welded by position.
  {
    struct KeyHash {
      size_t operator()(const std::array<int64_t, 3>& k) const {
        return std::hash<int64_t>()(k[0] * 73856093LL ^ k[1] * 19349663LL ^ k[2] * 83492791LL);
      }
    };
    std::unordered_map<std::array<int64_t, 3>, int, KeyHash> group_of_key;
    std::vector<int> group(n);
    for (size_t v = 0; v < n; ++v) {
      const std::array<int64_t, 3> key = {std::llround(verts[v].x() * 1e6),
                                          std::llround(verts[v].y() * 1e6),
                                          std::llround(verts[v].z() * 1e6)};
      group[v] = group_of_key.emplace(key, static_cast<int>(group_of_key.size())).first->second;
    }
    std::vector<Vector3d> acc(group_of_key.size(), Vector3d::Zero());
    for (size_t t = 0; t + 2 < avatar.indices.size(); t += 3) {
      const uint32_t a = avatar.indices[t], b = avatar.indices[t + 1], c = avatar.indices[t + 2];
      const Vector3d nrm = (verts[b] - verts[a]).cross(verts[c] - verts[a]);
      for (uint32_t i : {a, b, c}) acc[group[i]] += nrm;
    }
    for (size_t v = 0; v < n; ++v) {
      const Vector3d& a = acc[group[v]];
      avatar.bind_vertices[v].normal =
          a.norm() > 0 ? Eigen::Vector3f(a.normalized().cast<float>()) : Eigen::Vector3f::UnitZ();
    }
  }

  // Markers.
  std::vector<int> dominant(n);
  for (size_t v = 0; v < n; ++v) dominant[v] = bone_index[v][0];
  Vector3d head_offset(0, 0.005 * h, 0.050 * h);
  {
    Vector3d sum = Vector3d::Zero();
    double top = -std::numeric_limits<double>::infinity();
    int count = 0;
    for (size_t v = 0; v < n; ++v) {
      if (dominant[v] == kHead) sum += verts[v], ++count, top = std::max(top, verts[v].z());
    }
    if (count > 0) {
      head_offset = sum / count - q[kHead];
      // Not above the middle between the head joint and the crown: where only
      // the crown is head-weighted (the rigged figure's box head), the
      // centroid would sit on top of the head.
      head_offset.z() = std::min(head_offset.z(), 0.5 * (top - q[kHead].z()));
    }
  }
  std::array<double, 2> hand_length{0.108 * h, 0.108 * h};  // right, left
  std::array<Vector3d, 2> hand_tip;
  for (int side : {+1, -1}) {
    const int wrist = side > 0 ? kRightWrist : kLeftWrist;
    double best = -1;
    for (size_t v = 0; v < n; ++v) {
      const double along = side * (verts[v].x() - q[wrist].x());
      if (dominant[v] == wrist || (dominant[v] == wrist - 1 && along > 0))
        best = std::max(best, along);
    }
    if (best > 0) hand_length[side > 0 ? 0 : 1] = best;
    // Centred on the fingers' ends: the mean height and depth of the hand
    // vertices in the last 1.5% of the height (fingers that hang or bend off
    // the forearm axis keep the tip on the hand).
    Vector3d sum = Vector3d::Zero();
    int count = 0;
    for (size_t v = 0; v < n && best > 0; ++v) {
      const double along = side * (verts[v].x() - q[wrist].x());
      if ((dominant[v] == wrist || (dominant[v] == wrist - 1 && along > 0)) && along >= best - 0.015 * h)
        sum += verts[v] - q[wrist], ++count;
    }
    const int s = side > 0 ? 0 : 1;
    hand_tip[s] = Vector3d(side * hand_length[s], 0, 0);
    if (count > 0) hand_tip[s].y() = sum.y() / count, hand_tip[s].z() = sum.z() / count;
  }
  avatar.markers = {{"head", kHead, head_offset},
                    {"right_hand_tip", kRightWrist, hand_tip[0]},
                    {"left_hand_tip", kLeftWrist, hand_tip[1]}};

  // Body radii: the median distance to the surface along rays from the point,
  // across the body segment (or in all directions for the head).
  auto radius = [&](const Vector3d& centre, const Vector3d& axis, double fallback) {
    std::vector<Vector3d> directions;
    if (axis.isZero()) {
      const int count = 64;  // Fibonacci sphere
      for (int i = 0; i < count; ++i) {
        const double z = 1 - (2 * i + 1.0) / count, r = std::sqrt(1 - z * z),
                     phi = i * M_PI * (3 - std::sqrt(5.0));
        directions.emplace_back(r * std::cos(phi), r * std::sin(phi), z);
      }
    } else {
      const Vector3d a = axis.unitOrthogonal(), b = axis.cross(a).normalized();
      for (int i = 0; i < 16; ++i) {
        const double phi = 2 * M_PI * i / 16;
        directions.push_back(std::cos(phi) * a + std::sin(phi) * b);
      }
    }
    std::vector<double> hits;
    for (const Vector3d& d : directions) {
      const double t = RayHit(verts, avatar.indices, centre, d);
      if (std::isfinite(t)) hits.push_back(t);
    }
    // Most rays miss when the point lies outside the mesh.
    return 2 * hits.size() >= directions.size() ? Median(hits) : fallback;
  };
  auto both = [&](auto&& f) { return 0.5 * (f(+1) + f(-1)); };
  avatar.truth_radius["root"] = 0.0;
  avatar.truth_radius["waist"] = radius(q[kSpine], uz, 0.075 * h);
  avatar.truth_radius["neck"] = radius(q[kNeck], uz, 0.040 * h);
  avatar.truth_radius["head"] = radius(q[kHead] + head_offset, Vector3d::Zero(), 0.058 * h);
  const std::map<std::string, std::pair<int, double>> limbs = {
      {"shoulder", {kRightShoulder, 0.040}}, {"elbow", {kRightElbow, 0.025}},
      {"wrist", {kRightWrist, 0.018}},       {"hip", {kRightHip, 0.060}},
      {"knee", {kRightKnee, 0.034}},         {"ankle", {kRightAnkle, 0.025}}};
  for (const auto& [key, joint_fraction] : limbs) {
    const auto [right, fraction] = joint_fraction;
    const bool arm = right <= kRightWrist;
    avatar.truth_radius[key] = both([&](int s) {
      const int j = s > 0 ? right : Mirror(right);
      return radius(q[j], arm ? Vector3d(s * ux) : uz, fraction * h);
    });
  }
  // The hand tip lies on the surface: the hand's half thickness 1.5% of the
  // height behind it.
  avatar.truth_radius["hand_tip"] = both([&](int s) {
    const int j = s > 0 ? kRightWrist : kLeftWrist;
    const Vector3d& tip = hand_tip[s > 0 ? 0 : 1];
    return radius(q[j] + tip - Vector3d(s * std::min(std::abs(tip.x()), 0.015 * h), 0, 0), s * ux, 0.010 * h);
  });

  avatar.params.source = {{"file", path.string()},
                          {"convention", mapping.convention},
                          {"up_axis", up_used},
                          {"scale", scale},
                          {"joint_map", mapping.map},
                          {"unmapped_rig_joints", mapping.unmapped_rig_joints}};
  Log().info(
      "avatar import: {}: {} rig, up {}, {:.4g} m/unit, {} vertices, {} triangles, {:.3f} m "
      "tall{}{}",
      file, mapping.convention, up_used, scale, n, avatar.indices.size() / 3, h,
      mapping.unmapped_rig_joints.empty() ? "" : "; unmapped rig joints (follow their parents): ",
      JoinNames(mapping.unmapped_rig_joints, 12));
  return avatar;
}

}  // namespace

JointMapping MapRigJoints(const std::vector<std::string>& rig_joint_names,
                          const std::map<std::string, std::string>& overrides) {
  return MapJoints(rig_joint_names, overrides, "");
}

Avatar ImportRiggedAvatar(const std::filesystem::path& file, const ImportOptions& options) {
  std::error_code ec;
  if (!fs::exists(file, ec)) throw InputError(file.string(), "file", "no such file");
  if (!fs::is_regular_file(file, ec)) throw InputError(file.string(), "file", "not a regular file");
  const std::string ext = Lower(file.extension().string());
  const Rig rig = ext == ".gltf" || ext == ".glb" ? LoadGltf(file) : LoadAssimp(file);
  return BuildAvatar(rig, file, options);
}

}  // namespace irbench
