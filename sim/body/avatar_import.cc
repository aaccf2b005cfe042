#include "sim/body/avatar_import.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <unordered_map>

#include "common/error.h"
#include "common/logging.h"
#include "common/text.h"
#include "sim/body/internal/imported_rig.h"
#include "sim/body/internal/joint_naming.h"
#include "sim/body/internal/joint_topology.h"

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
//
// Step 1 is in gltf_import.cc and assimp_import.cc (with imported_rig.cc), step 2 in
// joint_naming.cc, steps 3 to 8 here.

namespace irbench {
namespace import_internal {
namespace {

namespace fs = std::filesystem;
using Eigen::Matrix3d;
using Eigen::Vector3d;

// Canonical joint names joined for a message.
std::string JoinCanonical(const std::vector<int>& joints) {
  std::vector<std::string> names;
  for (int j : joints) names.push_back(JointName(j));
  return JoinNames(names);
}

// The canonical joint on the other side (itself for the unsided ones).
int Mirror(int joint) {
  static const int kMirror[kJointCount] = {kPelvis,     kSpine,         kChest,         kNeck,
                                           kHead,       kLeftClavicle,  kLeftShoulder,  kLeftElbow,
                                           kLeftWrist,  kRightClavicle, kRightShoulder, kRightElbow,
                                           kRightWrist, kLeftHip,       kLeftKnee,      kLeftAnkle,
                                           kRightHip,   kRightKnee,     kRightAnkle};
  return kMirror[joint];
}

// Median of `v` (the mean of the middle two for an even count).
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

// Rejects a bad scale option, and a rig without triangles or with non-finite
// vertex or joint positions.
void CheckRig(const Rig& rig, const std::string& file, const ImportOptions& options) {
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
}

// Rig joint index of each canonical joint in `mapping`; -1 where unmapped.
std::array<int, kJointCount> RigJointOf(const JointMapping& mapping, const Rig& rig) {
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
  return rig_of;
}

// Whether every arm, torso and leg joint is mapped.
bool HasEveryChain(const std::array<int, kJointCount>& rig_of) {
  for (int j : {kPelvis, kNeck, kHead, kRightShoulder, kRightElbow, kRightWrist, kLeftShoulder, kLeftElbow,
                kLeftWrist, kRightHip, kRightKnee, kRightAnkle, kLeftHip, kLeftKnee, kLeftAnkle}) {
    if (rig_of[j] < 0) return false;
  }
  return true;
}

// Throws InputError(file, "skin") when an arm, torso or leg joint is unmapped.
void CheckChains(const std::array<int, kJointCount>& rig_of,
                 const Rig& rig,
                 const JointMapping& mapping,
                 const std::string& file) {
  std::vector<int> arms, torso, legs;
  for (int j : {kRightShoulder, kRightElbow, kRightWrist, kLeftShoulder, kLeftElbow, kLeftWrist}) {
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
std::vector<int> CollapsedJoints(const Rig& rig, const std::array<int, kJointCount>& rig_of) {
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
  return collapsed;
}

// Per vertex skinning weights on the canonical joints.
struct Weights {
  std::vector<std::array<uint8_t, 4>> bone_index;
  std::vector<std::array<float, 4>> bone_weight;
  std::vector<int> unweighted;  // vertices with no weight at all
};

// Per vertex the rig weights summed per collapsed canonical joint, the 4
// largest kept and renormalised to 1.
Weights CollapseWeights(const Rig& rig, const std::vector<int>& collapsed) {
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
  return {std::move(bone_index), std::move(bone_weight), std::move(unweighted)};
}

// Rotation taking the file's up axis to +z: the option's, or ("auto") the
// file axis nearest to pelvis -> head; `up_used` names it.
Matrix3d UpRotation(const Rig& rig,
                    const std::array<int, kJointCount>& rig_of,
                    const ImportOptions& options,
                    const std::string& file,
                    std::string& up_used) {
  auto rp = [&](int j) { return rig.joint_bind[rig_of[j]]; };
  Matrix3d up_rotation = Matrix3d::Identity();
  if (options.up_axis == UpAxis::kZ) {
    up_used = "z";
  } else if (options.up_axis == UpAxis::kY) {
    up_rotation = Eigen::AngleAxisd(M_PI / 2, Vector3d::UnitX()).toRotationMatrix();
    up_used = "y";
  } else {
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
  }
  return up_rotation;
}

// World from file frame: `up_rotation`, then the turn about +z that puts the
// right shoulder and hip at +x (the character then faces +y).
Matrix3d FacingFrame(const Rig& rig,
                     const std::array<int, kJointCount>& rig_of,
                     const Matrix3d& up_rotation,
                     const std::string& file) {
  auto rp = [&](int j) { return rig.joint_bind[rig_of[j]]; };
  Vector3d right =
      up_rotation * ((rp(kRightShoulder) - rp(kLeftShoulder)) + (rp(kRightHip) - rp(kLeftHip)));
  right.z() = 0;
  if (right.norm() < 1e-9)
    throw InputError(file, "skin",
                     "cannot tell the facing: the left and right shoulders and hips coincide");
  return Eigen::AngleAxisd(-std::atan2(right.y(), right.x()), Vector3d::UnitZ())
             .toRotationMatrix() *
         up_rotation;
}

// Metres per file unit: the option, else the file's unit; with no unit,
// centimetres when the height is implausible in file units and plausible in cm.
double FileScale(const Rig& rig,
                 const ImportOptions& options,
                 const Matrix3d& frame,
                 const std::string& file) {
  double scale = options.scale > 0 ? options.scale : rig.unit_scale;
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (const Vector3d& v : rig.position) {
    const double z = (frame * v).z();
    lo = std::min(lo, z), hi = std::max(hi, z);
  }
  const double height = (hi - lo) * scale;
  if (options.scale == 0 && !rig.unit_known && (height < 1.0 || height > 2.3) &&
      height * 0.01 >= 1.0 && height * 0.01 <= 2.3) {
    Log().info("avatar import: {}: {:.1f} units tall and no unit in the file: reading centimetres",
               file, hi - lo);
    scale *= 0.01;
  }
  return scale;
}

// Whether the feet (the ankle-dominated vertices) point backwards (-y), i.e.
// the rig's sides are mirrored.
bool FeetPointBackwards(const std::vector<Vector3d>& verts,
                        const std::array<Vector3d, kJointCount>& p,
                        const Weights& weights) {
  const size_t n = verts.size();
  const std::vector<std::array<uint8_t, 4>>& bone_index = weights.bone_index;
  const std::vector<std::array<float, 4>>& bone_weight = weights.bone_weight;
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
  return count >= 8 && forward < -0.25 * spread;
}

// Swaps left and right in the canonical -> rig map, the weights and `mapping`
// (the rig's side names are the character's other side).
void SwapSides(std::array<int, kJointCount>& rig_of,
               Weights& weights,
               JointMapping& mapping,
               const std::string& file) {
  if (mapping.convention == "hierarchy") {  // the sides were a guess
    Log().debug("avatar import: {}: the feet tell the character's left from right", file);
  } else {
    Log().warn(
        "avatar import: {}: the feet point backwards: the rig's left/right joint names are the "
        "character's right/left; swapping them",
        file);
  }
  const size_t n = weights.bone_index.size();
  std::vector<std::array<uint8_t, 4>>& bone_index = weights.bone_index;
  std::array<int, kJointCount> swapped;
  for (int j = 0; j < kJointCount; ++j) swapped[j] = rig_of[Mirror(j)];
  rig_of = swapped;
  for (size_t v = 0; v < n; ++v) {
    for (int k = 0; k < 4; ++k) bone_index[v][k] = static_cast<uint8_t>(Mirror(bone_index[v][k]));
  }
  std::map<std::string, std::string> map;
  for (const auto& [canonical, rig_name] : mapping.map)
    map[JointName(Mirror(*JointFromName(canonical)))] = rig_name;
  mapping.map = map;
}

// The rig in the world frame, in metres, before re-posing.
struct Placement {
  std::array<Vector3d, kJointCount> p;  // canonical joints (the mapped ones)
  std::vector<Vector3d> verts;
  double scale = 0;  // metres per file unit
  std::string up_used;
};

// Frame: up axis, facing, scale. Repeated once with the sides swapped when
// the feet point backwards.
Placement PlaceRig(const Rig& rig,
                   const ImportOptions& options,
                   const std::string& file,
                   std::array<int, kJointCount>& rig_of,
                   Weights& weights,
                   JointMapping& mapping) {
  const size_t n = rig.position.size();
  Placement placed;
  std::array<Vector3d, kJointCount>& p = placed.p;
  std::vector<Vector3d>& verts = placed.verts;
  verts.resize(n);
  double& scale = placed.scale;
  Matrix3d frame = Matrix3d::Identity();
  for (int attempt = 0; attempt < 2; ++attempt) {
    auto rp = [&](int j) { return rig.joint_bind[rig_of[j]]; };
    const Matrix3d up_rotation = UpRotation(rig, rig_of, options, file, placed.up_used);
    frame = FacingFrame(rig, rig_of, up_rotation, file);
    scale = FileScale(rig, options, frame, file);
    for (size_t v = 0; v < n; ++v) verts[v] = scale * (frame * rig.position[v]);
    for (int j = 0; j < kJointCount; ++j) {
      if (rig_of[j] >= 0) p[j] = scale * (frame * rp(j));
    }
    // The feet must point forward (+y); else the rig's sides are mirrored.
    if (attempt == 0 && FeetPointBackwards(verts, p, weights)) {
      SwapSides(rig_of, weights, mapping, file);
      continue;
    }
    break;
  }
  return placed;
}

// Unmapped spine, chest and clavicles, interpolated between their neighbours.
void FillUnmappedJoints(const std::array<int, kJointCount>& rig_of,
                        std::array<Vector3d, kJointCount>& p) {
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
}

// Vertices with no weight at all go with the nearest joint.
void AssignUnweighted(const std::vector<Vector3d>& verts,
                      const std::array<Vector3d, kJointCount>& p,
                      Weights& weights) {
  for (int v : weights.unweighted) {
    int best = kPelvis;
    for (int j = 0; j < kJointCount; ++j) {
      if ((verts[v] - p[j]).squaredNorm() < (verts[v] - p[best]).squaredNorm()) best = j;
    }
    weights.bone_index[v] = {static_cast<uint8_t>(best), 0, 0, 0};
    weights.bone_weight[v] = {1, 0, 0, 0};
  }
}

// World rotations re-posing the joints `p` into the canonical T-pose, each the
// smallest rotation on top of its parent's that aims the bone.
std::array<Matrix3d, kJointCount> TPoseRotations(const std::array<Vector3d, kJointCount>& p,
                                                 const std::string& file) {
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
  return rot;
}

// Re-posed joints: each joint's offset from its parent turned by the parent's
// rotation.
std::array<Vector3d, kJointCount> TPoseJoints(const std::array<Vector3d, kJointCount>& p,
                                              const std::array<Matrix3d, kJointCount>& rot) {
  std::array<Vector3d, kJointCount> q;
  for (int j = 0; j < kJointCount; ++j) {
    const int parent = JointParent(j);
    q[j] = parent < 0 ? p[j] : Vector3d(q[parent] + rot[parent] * (p[j] - p[parent]));
  }
  return q;
}

// Linear blend skinning of `verts` from the joints `p` to the re-posed `q`.
void SkinToTPose(std::vector<Vector3d>& verts,
                 const Weights& weights,
                 const std::array<Vector3d, kJointCount>& p,
                 const std::array<Vector3d, kJointCount>& q,
                 const std::array<Matrix3d, kJointCount>& rot) {
  const size_t n = verts.size();
  for (size_t v = 0; v < n; ++v) {
    Vector3d out = Vector3d::Zero();
    for (int k = 0; k < 4; ++k) {
      const float w = weights.bone_weight[v][k];
      if (w == 0) continue;
      const int j = weights.bone_index[v][k];
      out += w * (q[j] + rot[j] * (verts[v] - p[j]));
    }
    verts[v] = out;
  }
}

// Feet on the floor, pelvis over the origin; returns the height, which must be
// 1.0..2.3 m (else InputError(file, "height")).
double PlaceOnFloor(std::vector<Vector3d>& verts,
                    std::array<Vector3d, kJointCount>& q,
                    double scale,
                    const std::string& file) {
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
  return h;
}

// The avatar's parameters, skeleton, triangles, weights and bind vertices
// (positions `verts`, the rig's albedo); normals and markers still to come.
Avatar MakeAvatar(const Rig& rig,
                  const fs::path& path,
                  const ImportOptions& options,
                  double h,
                  const std::array<Vector3d, kJointCount>& q,
                  const Weights& weights,
                  const std::vector<Vector3d>& verts) {
  const size_t n = verts.size();
  Avatar avatar;
  avatar.params.name = options.name.empty() ? path.stem().string() : options.name;
  avatar.params.kind = "mesh";
  avatar.params.height_m = h;
  avatar.params.build = 1.0;
  for (int j = 0; j < kJointCount; ++j) avatar.skeleton.bind_position[j] = q[j];
  avatar.indices = rig.indices;
  avatar.bone_index = weights.bone_index;
  avatar.bone_weight = weights.bone_weight;
  avatar.bind_vertices.resize(n);
  for (size_t v = 0; v < n; ++v) {
    MeshVertex& mv = avatar.bind_vertices[v];
    mv.position = verts[v].cast<float>();
    mv.albedo = rig.albedo[v];
    mv.emissive = 0.0f;
  }
  return avatar;
}

// Hash of a vertex position rounded to micrometres.
struct PositionKeyHash {
  size_t operator()(const std::array<int64_t, 3>& k) const {
    // Unsigned: the multiplications wrap instead of overflowing.
    return std::hash<uint64_t>()(static_cast<uint64_t>(k[0]) * 73856093ull ^
                                 static_cast<uint64_t>(k[1]) * 19349663ull ^
                                 static_cast<uint64_t>(k[2]) * 83492791ull);
  }
};

// Normals: area-weighted over the re-posed mesh, welded by position (smooth
// across UV seams).
void WeldedNormals(const std::vector<Vector3d>& verts, Avatar& avatar) {
  const size_t n = verts.size();
  std::unordered_map<std::array<int64_t, 3>, int, PositionKeyHash> group_of_key;
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

// The "head" marker's offset from the head joint: the centroid of the
// head-dominated vertices, not above halfway from the joint to their top.
Vector3d HeadOffset(const std::vector<Vector3d>& verts,
                    const std::vector<int>& dominant,
                    const std::array<Vector3d, kJointCount>& q,
                    double h) {
  const size_t n = verts.size();
  Vector3d head_offset(0, 0.005 * h, 0.050 * h);
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
  return head_offset;
}

// The hand tips in the wrist frames (right, left): (+-L, 0, 0), L the hand's
// extent along the forearm, centred on the fingers' ends in y and z.
std::array<Vector3d, 2> HandTips(const std::vector<Vector3d>& verts,
                                 const std::vector<int>& dominant,
                                 const std::array<Vector3d, kJointCount>& q,
                                 double h) {
  const size_t n = verts.size();
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
      if ((dominant[v] == wrist || (dominant[v] == wrist - 1 && along > 0)) &&
          along >= best - 0.015 * h)
        sum += verts[v] - q[wrist], ++count;
    }
    const int s = side > 0 ? 0 : 1;
    hand_tip[s] = Vector3d(side * hand_length[s], 0, 0);
    if (count > 0) hand_tip[s].y() = sum.y() / count, hand_tip[s].z() = sum.z() / count;
  }
  return hand_tip;
}

// Body radius at `centre`: the median distance to the mesh along 16 rays
// across `axis`, or for a zero axis 64 in all directions; `fallback` when
// most rays miss.
double BodyRadius(const std::vector<Vector3d>& verts,
                  const std::vector<uint32_t>& indices,
                  const Vector3d& centre,
                  const Vector3d& axis,
                  double fallback) {
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
    const double t = RayHit(verts, indices, centre, d);
    if (std::isfinite(t)) hits.push_back(t);
  }
  // Most rays miss when the point lies outside the mesh.
  return 2 * hits.size() >= directions.size() ? Median(hits) : fallback;
}

// Body radii (truth_radius): how deep each tracked point lies under the
// surface, across its body segment; both sides averaged.
void TruthRadii(Avatar& avatar,
                const std::vector<Vector3d>& verts,
                const std::array<Vector3d, kJointCount>& q,
                const Vector3d& head_offset,
                const std::array<Vector3d, 2>& hand_tip,
                double h) {
  const Vector3d ux = Vector3d::UnitX(), uz = Vector3d::UnitZ();
  auto radius = [&](const Vector3d& centre, const Vector3d& axis, double fallback) {
    return BodyRadius(verts, avatar.indices, centre, axis, fallback);
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
    avatar.truth_radius[key] = both([&, right = right, fraction = fraction](int s) {
      const int j = s > 0 ? right : Mirror(right);
      return radius(q[j], arm ? Vector3d(s * ux) : uz, fraction * h);
    });
  }
  // The hand tip lies on the surface: the hand's half thickness 1.5% of the
  // height behind it.
  avatar.truth_radius["hand_tip"] = both([&](int s) {
    const int j = s > 0 ? kRightWrist : kLeftWrist;
    const Vector3d& tip = hand_tip[s > 0 ? 0 : 1];
    return radius(q[j] + tip - Vector3d(s * std::min(std::abs(tip.x()), 0.015 * h), 0, 0), s * ux,
                  0.010 * h);
  });
}

// The canonical avatar from a loaded rig (steps 2 to 8 above).
Avatar BuildAvatar(const Rig& rig, const fs::path& path, const ImportOptions& options) {
  const std::string file = path.string();
  CheckRig(rig, file, options);

  JointMapping mapping = MapJoints(rig.joint_name, options.joint_map, file);
  std::array<int, kJointCount> rig_of = RigJointOf(mapping, rig);
  if (options.joint_map.empty() && !HasEveryChain(rig_of)) {
    // No table names every chain: the hierarchy's shape maps the rig.
    try {
      mapping = MapJointsByHierarchy(rig, file);
    } catch (const InputError& e) {
      throw InputError(file, e.field(),
                       e.message() + " (no name table maps every chain either, best '" + mapping.convention +
                           "'; rig joints: " + JoinNames(rig.joint_name) + "; pass a joint map)");
    }
    rig_of = RigJointOf(mapping, rig);
  }
  CheckChains(rig_of, rig, mapping, file);
  const std::vector<int> collapsed = CollapsedJoints(rig, rig_of);
  // Collapsed weights (before any side swap).
  Weights weights = CollapseWeights(rig, collapsed);
  Placement placed = PlaceRig(rig, options, file, rig_of, weights, mapping);
  std::array<Vector3d, kJointCount>& p = placed.p;
  std::vector<Vector3d>& verts = placed.verts;
  const double scale = placed.scale;
  const std::string& up_used = placed.up_used;
  const size_t n = rig.position.size();
  FillUnmappedJoints(rig_of, p);
  AssignUnweighted(verts, p, weights);

  // Re-pose into the T-pose.
  const std::array<Matrix3d, kJointCount> rot = TPoseRotations(p, file);
  std::array<Vector3d, kJointCount> q = TPoseJoints(p, rot);
  SkinToTPose(verts, weights, p, q, rot);
  // A rig whose bind matrices are degenerate can throw the mesh anywhere: a
  // person stays within a kilometre (found by fuzz/gltf_fuzz).
  for (const Vector3d& v : verts) {
    if (!v.allFinite() || v.cwiseAbs().maxCoeff() > 1e3) {
      throw InputError(file, "skins", "re-posed into the T-pose, the mesh is not finite or lies beyond 1 km");
    }
  }
  const double h = PlaceOnFloor(verts, q, scale, file);

  Avatar avatar = MakeAvatar(rig, path, options, h, q, weights, verts);
  WeldedNormals(verts, avatar);

  // Markers.
  std::vector<int> dominant(n);
  for (size_t v = 0; v < n; ++v) dominant[v] = weights.bone_index[v][0];
  const Vector3d head_offset = HeadOffset(verts, dominant, q, h);
  const std::array<Vector3d, 2> hand_tip = HandTips(verts, dominant, q, h);
  avatar.markers = {{"head", kHead, head_offset},
                    {"right_hand_tip", kRightWrist, hand_tip[0]},
                    {"left_hand_tip", kLeftWrist, hand_tip[1]}};
  TruthRadii(avatar, verts, q, head_offset, hand_tip, h);

  avatar.params.source = {
      {"file", path.string()},    {"convention", mapping.convention},
      {"up_axis", up_used},       {"scale", scale},
      {"joint_map", mapping.map}, {"unmapped_rig_joints", mapping.unmapped_rig_joints}};
  Log().info(
      "avatar import: {}: {} rig, up {}, {:.4g} m/unit, {} vertices, {} triangles, {:.3f} m "
      "tall{}{}",
      file, mapping.convention, up_used, scale, n, avatar.indices.size() / 3, h,
      mapping.unmapped_rig_joints.empty() ? "" : "; unmapped rig joints (follow their parents): ",
      JoinNames(mapping.unmapped_rig_joints, 12));
  return avatar;
}

}  // namespace
}  // namespace import_internal

Avatar ImportRiggedAvatar(const std::filesystem::path& file, const ImportOptions& options) {
  std::error_code ec;
  if (!std::filesystem::exists(file, ec)) throw InputError(file.string(), "file", "no such file");
  if (!std::filesystem::is_regular_file(file, ec))
    throw InputError(file.string(), "file", "not a regular file");
  const std::string ext = AsciiLower(file.extension().string());
  const import_internal::Rig rig = ext == ".gltf" || ext == ".glb"
                                       ? import_internal::LoadGltf(file)
                                       : import_internal::LoadAssimp(file);
  return import_internal::BuildAvatar(rig, file, options);
}

std::optional<UpAxis> ParseUpAxis(const std::string& name) {
  if (name == "auto") return UpAxis::kAuto;
  if (name == "y") return UpAxis::kY;
  if (name == "z") return UpAxis::kZ;
  return std::nullopt;
}

}  // namespace irbench
