#include "sim/body/avatar.h"
#include "common/error.h"
#include "sim/scene/materials.h"

#include <cctype>
#include <cmath>
#include <map>
#include <mutex>
#include <optional>

#include "common/json_reader.h"
#include "sim/body/avatar_import.h"
#include "sim/body/parametric.h"

namespace irbench {
namespace {

// One cross-section of a tube.
struct Ring {
  Eigen::Vector3d center;
  Eigen::Vector3d axis_a, axis_b;  // unit, perpendicular to the tube
  double ra, rb;                   // semi-axes, metres
  int bone0, bone1;
  float weight0;  // weight of bone0; bone1 gets the rest
  NirReflectance albedo;
};

class MeshBuilder {
 public:
  explicit MeshBuilder(Avatar& avatar) : avatar_(avatar) {}

  // A closed tube through `rings`, with domed caps at both ends.
  void Tube(const std::vector<Ring>& rings, int segments = 20) {
    const uint32_t first_vertex = static_cast<uint32_t>(avatar_.bind_vertices.size());
    const size_t first_index = avatar_.indices.size();
    std::vector<Ring> all;
    // Domed caps: extra shrinking rings beyond each end.
    auto cap = [&](const Ring& end, const Eigen::Vector3d& outward, bool at_start) {
      std::vector<Ring> caps;
      const double depth = 0.8 * std::min(end.ra, end.rb);
      for (double f : {0.5, 0.8, 0.95}) {
        Ring r = end;
        const double angle = f * M_PI / 2;
        r.center = end.center + outward * depth * std::sin(angle);
        r.ra = end.ra * std::cos(angle);
        r.rb = end.rb * std::cos(angle);
        caps.push_back(r);
      }
      if (at_start) std::reverse(caps.begin(), caps.end());
      return caps;
    };
    const Eigen::Vector3d dir_start = (rings[0].center - rings[1].center).normalized();
    const Eigen::Vector3d dir_end =
        (rings.back().center - rings[rings.size() - 2].center).normalized();
    for (const Ring& r : cap(rings.front(), dir_start, true)) all.push_back(r);
    all.insert(all.end(), rings.begin(), rings.end());
    for (const Ring& r : cap(rings.back(), dir_end, false)) all.push_back(r);

    for (const Ring& r : all) {
      for (int i = 0; i < segments; ++i) {
        const double phi = 2 * M_PI * i / segments;
        const Eigen::Vector3d p =
            r.center + r.axis_a * (r.ra * std::cos(phi)) + r.axis_b * (r.rb * std::sin(phi));
        AddVertex(p, r);
      }
    }
    // Apexes closing both ends.
    const Ring& first = all.front();
    const Ring& last = all.back();
    const double first_depth = 0.8 * std::min(rings.front().ra, rings.front().rb);
    const double last_depth = 0.8 * std::min(rings.back().ra, rings.back().rb);
    const uint32_t apex0 = AddVertex(rings.front().center + dir_start * first_depth, first);
    const uint32_t apex1 = AddVertex(rings.back().center + dir_end * last_depth, last);

    const uint32_t n_rings = static_cast<uint32_t>(all.size());
    const uint32_t s = static_cast<uint32_t>(segments);
    for (uint32_t k = 0; k + 1 < n_rings; ++k) {
      for (uint32_t i = 0; i < s; ++i) {
        const uint32_t a = first_vertex + k * s + i;
        const uint32_t b = first_vertex + k * s + (i + 1) % s;
        const uint32_t c = a + s, d = b + s;
        avatar_.indices.insert(avatar_.indices.end(), {a, b, d, a, d, c});
      }
    }
    for (uint32_t i = 0; i < s; ++i) {
      avatar_.indices.insert(avatar_.indices.end(),
                             {apex0, first_vertex + (i + 1) % s, first_vertex + i});
      const uint32_t base = first_vertex + (n_rings - 1) * s;
      avatar_.indices.insert(avatar_.indices.end(), {apex1, base + i, base + (i + 1) % s});
    }
    ComputeNormals(first_vertex, first_index);
  }

 private:
  uint32_t AddVertex(const Eigen::Vector3d& p, const Ring& r) {
    MeshVertex v;
    v.position = p.cast<float>();
    v.SetReflectance(r.albedo);
    avatar_.bind_vertices.push_back(v);
    avatar_.bone_index.push_back({static_cast<uint8_t>(r.bone0), static_cast<uint8_t>(r.bone1), 0, 0});
    avatar_.bone_weight.push_back({r.weight0, 1.0f - r.weight0, 0, 0});
    return static_cast<uint32_t>(avatar_.bind_vertices.size() - 1);
  }

  // Area-weighted smooth normals over the tube just added, oriented outwards.
  void ComputeNormals(uint32_t first_vertex, size_t first_index) {
    auto& verts = avatar_.bind_vertices;
    std::vector<Eigen::Vector3f> acc(verts.size() - first_vertex, Eigen::Vector3f::Zero());
    Eigen::Vector3f centroid = Eigen::Vector3f::Zero();
    for (size_t i = first_vertex; i < verts.size(); ++i) centroid += verts[i].position;
    centroid /= float(verts.size() - first_vertex);
    float orientation = 0;
    for (size_t t = first_index; t < avatar_.indices.size(); t += 3) {
      const uint32_t a = avatar_.indices[t], b = avatar_.indices[t + 1], c = avatar_.indices[t + 2];
      const Eigen::Vector3f n =
          (verts[b].position - verts[a].position).cross(verts[c].position - verts[a].position);
      orientation += n.dot(verts[a].position - centroid);
      for (uint32_t v : {a, b, c}) acc[v - first_vertex] += n;
    }
    const float sign = orientation >= 0 ? 1.0f : -1.0f;
    for (size_t i = 0; i < acc.size(); ++i) {
      verts[first_vertex + i].normal = (sign * acc[i]).normalized();
    }
  }

  Avatar& avatar_;
};

Eigen::Vector3d Perpendicular(const Eigen::Vector3d& dir, const Eigen::Vector3d& reference) {
  return (reference - reference.dot(dir) * dir).normalized();
}

// Rings along a limb bone from joint `a` to `b`; weights blend with the parent
// bone over the first 20% and with the child bone over the last 20%.
std::vector<Ring> LimbRings(const Eigen::Vector3d& p0,
                            const Eigen::Vector3d& p1,
                            const Eigen::Vector3d& reference_a,
                            double ra0,
                            double rb0,
                            double ra1,
                            double rb1,
                            int parent_bone,
                            int bone,
                            int child_bone,
                            NirReflectance albedo,
                            int n = 10) {
  std::vector<Ring> rings;
  const Eigen::Vector3d dir = (p1 - p0).normalized();
  const Eigen::Vector3d axis_a = Perpendicular(dir, reference_a);
  const Eigen::Vector3d axis_b = dir.cross(axis_a);
  for (int k = 0; k <= n; ++k) {
    const double t = double(k) / n;
    Ring r;
    r.center = p0 + (p1 - p0) * t;
    r.axis_a = axis_a;
    r.axis_b = axis_b;
    // Slight muscle bulge in the first half.
    const double bulge = 1.0 + 0.08 * std::sin(M_PI * std::min(1.0, t * 1.6));
    r.ra = (ra0 + (ra1 - ra0) * t) * bulge;
    r.rb = (rb0 + (rb1 - rb0) * t) * bulge;
    r.albedo = albedo;
    r.bone0 = bone;
    if (t < 0.2 && parent_bone >= 0) {
      r.bone1 = parent_bone;
      r.weight0 = static_cast<float>(0.5 + 0.5 * t / 0.2);
    } else if (t > 0.8 && child_bone >= 0) {
      r.bone1 = child_bone;
      r.weight0 = static_cast<float>(1.0 - 0.5 * (t - 0.8) / 0.2);
    } else {
      r.bone1 = bone;
      r.weight0 = 1.0f;
    }
    rings.push_back(r);
  }
  return rings;
}

}  // namespace

Avatar BuildTubeAvatar(const AvatarParams& params) {
  Avatar avatar;
  avatar.params = params;
  const double h = params.height_m;
  const double g = params.build;
  auto& bind = avatar.skeleton.bind_position;
  // Joint centres as fractions of height (after Drillis & Contini).
  bind[kPelvis] = {0, 0, 0.530 * h};
  bind[kSpine] = {0, 0, 0.600 * h};
  bind[kChest] = {0, 0, 0.710 * h};
  bind[kNeck] = {0, 0, 0.818 * h};
  bind[kHead] = {0, 0, 0.885 * h};
  for (int side : {+1, -1}) {
    const int clav = side > 0 ? kRightClavicle : kLeftClavicle;
    bind[clav] = {side * 0.020 * h, 0, 0.805 * h};
    bind[clav + 1] = {side * 0.105 * h, 0, 0.812 * h};  // shoulder
    bind[clav + 2] = {side * 0.277 * h, 0, 0.812 * h};  // elbow
    bind[clav + 3] = {side * 0.434 * h, 0, 0.812 * h};  // wrist
    const int hip = side > 0 ? kRightHip : kLeftHip;
    bind[hip] = {side * 0.050 * h, 0, 0.500 * h};
    bind[hip + 1] = {side * 0.052 * h, 0, 0.285 * h};  // knee
    bind[hip + 2] = {side * 0.054 * h, 0, 0.039 * h};  // ankle
  }
  const double hand_length = 0.108 * h;
  avatar.markers = {{"head", kHead, {0, 0.005 * h, 0.050 * h}},
                    {"right_hand_tip", kRightWrist, {hand_length, 0, 0}},
                    {"left_hand_tip", kLeftWrist, {-hand_length, 0, 0}}};

  MeshBuilder builder(avatar);
  const Eigen::Vector3d ux = Eigen::Vector3d::UnitX(), uy = Eigen::Vector3d::UnitY();

  // Torso: elliptical rings from the crotch to the base of the neck; weights
  // blend pelvis -> spine -> chest with height.
  {
    struct Profile {
      double z, half_width, half_depth, y_offset;
    };
    const std::vector<Profile> profile = {
        {0.455, 0.075, 0.050, -0.004}, {0.490, 0.092, 0.060, -0.006}, {0.530, 0.097, 0.063, -0.006},
        {0.570, 0.090, 0.058, -0.002}, {0.610, 0.084, 0.056, 0.002},  {0.650, 0.086, 0.060, 0.004},
        {0.690, 0.094, 0.064, 0.006},  {0.730, 0.100, 0.066, 0.006},  {0.770, 0.101, 0.062, 0.002},
        {0.800, 0.090, 0.052, -0.004}, {0.822, 0.060, 0.040, -0.006}};
    std::vector<Ring> rings;
    const double zp = 0.545, zs = 0.630, zc = 0.730;  // where each bone dominates fully
    for (const Profile& p : profile) {
      Ring r;
      r.center = {0, p.y_offset * h, p.z * h};
      r.axis_a = ux;
      r.axis_b = uy;
      r.ra = p.half_width * h * g;
      r.rb = p.half_depth * h * g;
      r.albedo = p.z < 0.52 ? params.pants_albedo : params.shirt_albedo;
      if (p.z <= zp) {
        r.bone0 = kPelvis, r.bone1 = kPelvis, r.weight0 = 1;
      } else if (p.z <= zs) {
        r.bone0 = kPelvis, r.bone1 = kSpine, r.weight0 = float((zs - p.z) / (zs - zp));
      } else if (p.z <= zc) {
        r.bone0 = kSpine, r.bone1 = kChest, r.weight0 = float((zc - p.z) / (zc - zs));
      } else {
        r.bone0 = kChest, r.bone1 = kChest, r.weight0 = 1;
      }
      rings.push_back(r);
    }
    builder.Tube(rings, 28);
  }
  // Neck.
  builder.Tube(LimbRings({0, -0.004 * h, 0.800 * h}, {0, 0.002 * h, 0.895 * h}, ux,
                         0.032 * h * std::sqrt(g), 0.034 * h * std::sqrt(g), 0.030 * h, 0.032 * h,
                         kChest, kNeck, kHead, params.skin_albedo, 6),
               16);
  // Head: an egg-shaped lathe from the chin to the crown.
  {
    std::vector<Ring> rings;
    const int n = 12;
    for (int k = 0; k <= n; ++k) {
      const double u = double(k) / n;  // 0 chin .. 1 crown
      const double z = (0.870 + 0.118 * u) * h;
      const double s = std::pow(std::sin(M_PI * (0.12 + 0.80 * u)), 0.7);
      Ring r;
      r.center = {0, (0.008 - 0.006 * u) * h, z};
      r.axis_a = ux;
      r.axis_b = uy;
      r.ra = 0.046 * h * s;
      r.rb = 0.056 * h * s;
      r.bone0 = kHead;
      r.bone1 = kHead;
      r.weight0 = 1;
      r.albedo = u > 0.55 ? params.hair_albedo : params.skin_albedo;
      rings.push_back(r);
    }
    builder.Tube(rings, 20);
  }
  for (int side : {+1, -1}) {
    const int clav = side > 0 ? kRightClavicle : kLeftClavicle;
    const int shoulder = clav + 1, elbow = clav + 2, wrist = clav + 3;
    // Shoulder girdle from the clavicle root to just past the shoulder joint.
    builder.Tube(LimbRings(bind[clav], bind[shoulder] + Eigen::Vector3d(side * 0.01 * h, 0, 0), uy,
                           0.040 * h * g, 0.034 * h * g, 0.034 * h * g, 0.032 * h * g, kChest, clav,
                           shoulder, params.shirt_albedo, 6),
                 16);
    builder.Tube(LimbRings(bind[shoulder], bind[elbow], uy, 0.030 * h * g, 0.030 * h * g,
                           0.022 * h * g, 0.021 * h * g, clav, shoulder, elbow, params.shirt_albedo),
                 18);
    builder.Tube(LimbRings(bind[elbow], bind[wrist], uy, 0.022 * h * g, 0.021 * h * g,
                           0.016 * h * std::sqrt(g), 0.012 * h * std::sqrt(g), shoulder, elbow, wrist,
                           params.skin_albedo),
                 18);
    // Hand: flat, palm down in the T-pose.
    builder.Tube(LimbRings(bind[wrist], bind[wrist] + Eigen::Vector3d(side * (hand_length - 0.0048 * h), 0, 0),
                           uy, 0.020 * h, 0.009 * h, 0.016 * h, 0.006 * h, elbow, wrist, -1,
                           params.skin_albedo, 6),
                 12);
    const int hip = side > 0 ? kRightHip : kLeftHip;
    const int knee = hip + 1, ankle = hip + 2;
    builder.Tube(LimbRings(bind[hip] + Eigen::Vector3d(0, 0, 0.02 * h), bind[knee], ux,
                           0.050 * h * g, 0.052 * h * g, 0.031 * h * g, 0.031 * h * g, kPelvis, hip,
                           knee, params.pants_albedo),
                 18);
    builder.Tube(LimbRings(bind[knee], bind[ankle], ux, 0.031 * h * g, 0.033 * h * g, 0.019 * h,
                           0.020 * h, hip, knee, ankle, params.pants_albedo),
                 18);
    // Foot: from the heel forward, its sole on the floor.
    const double foot_z = 0.021 * h;
    builder.Tube(LimbRings({bind[ankle].x(), -0.035 * h, foot_z}, {bind[ankle].x(), 0.110 * h, foot_z * 0.8},
                           ux, 0.026 * h, 0.021 * h, 0.024 * h, 0.012 * h, knee, ankle, -1,
                           params.shoe_albedo, 8),
                 12);
  }
  avatar.truth_radius = {
      {"root", 0.0},           {"waist", 0.075 * h * g},  {"neck", 0.040 * h},
      {"head", 0.058 * h},     {"shoulder", 0.040 * h * g}, {"elbow", 0.025 * h * g},
      {"wrist", 0.018 * h},    {"hand_tip", 0.010 * h},    {"hip", 0.060 * h * g},
      {"knee", 0.034 * h * g}, {"ankle", 0.025 * h}};
  return avatar;
}

namespace {

std::string LowerExtension(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

// kind "mesh": a rigged mesh file imported with the options in the JSON
// (docs/avatars.md, "Imported rigged meshes").
Avatar LoadMeshAvatar(const std::filesystem::path& path, const JsonNode& root, const std::string& name,
                      const nlohmann::json& style) {
  for (const char* key : {"height_m", "build", "albedo", "shape"}) {
    if (root.Has(key)) {
      root[key].Fail("not used by imported meshes (their size comes from the file and \"scale\", "
                     "their albedo from its materials)");
    }
  }
  std::filesystem::path file = root.GetString("file");
  if (file.is_relative()) file = path.parent_path() / file;
  if (!std::filesystem::is_regular_file(file)) root["file"].Fail("no such file: " + file.string());
  ImportOptions options;
  options.name = name;
  if (root.Has("scale")) {
    options.scale = root.GetDouble("scale");
    if (!(options.scale > 0 && options.scale <= 1000)) root["scale"].Fail("must be in (0, 1000] metres per file unit");
  }
  const std::optional<UpAxis> up_axis = ParseUpAxis(root.GetString("up_axis", "auto"));
  if (!up_axis) root["up_axis"].Fail("must be auto, y or z");
  options.up_axis = *up_axis;
  if (root.Has("joint_map")) {
    const JsonNode m = root["joint_map"];
    if (!m.raw().is_object()) m.Fail("must be an object: canonical joint name -> rig joint name");
    for (const auto& [canonical, rig] : m.raw().items()) {
      if (!rig.is_string()) m[canonical].Fail("must be a string (the rig's joint name, or \"\" to leave it unmapped)");
      options.joint_map[canonical] = rig.get<std::string>();
    }
  }
  Avatar avatar;
  try {
    avatar = ImportRiggedAvatar(file, options);
  } catch (const InputError& e) {
    // Option errors belong to the JSON; file, skin and height errors to the mesh.
    if (e.field().rfind("joint_map", 0) == 0 || e.field() == "scale" || e.field() == "up_axis") {
      throw InputError(path.string(), e.field(), e.message());
    }
    throw;
  }
  avatar.params.style = style;
  return avatar;
}

// A parametric or tube avatar from its file's JSON: checked, then built.
Avatar BuildDescribedAvatar(const JsonNode& root, AvatarParams params) {
  for (const char* key : {"file", "scale", "up_axis", "joint_map"}) {
    if (root.Has(key)) root[key].Fail("only imported (kind \"mesh\") avatars have it");
  }
  params.height_m = root.GetDouble("height_m");
  if (params.height_m < 1.0 || params.height_m > 2.3) root["height_m"].Fail("must be in 1.0..2.3 m");
  params.build = root.GetDouble("build", 1.0);
  if (params.build < 0.6 || params.build > 1.8) root["build"].Fail("must be in 0.6..1.8");
  if (root.Has("albedo")) {
    const JsonNode a = root["albedo"];
    a.CheckKeys({"skin", "shirt", "pants", "shoes", "hair"});
    auto read = [&](const char* key, NirReflectance& out) {
      if (a.Has(key)) out = ReadReflectance(a[key]);
    };
    read("skin", params.skin_albedo);
    read("shirt", params.shirt_albedo);
    read("pants", params.pants_albedo);
    read("shoes", params.shoe_albedo);
    read("hair", params.hair_albedo);
  }
  if (params.kind == "tube") {
    if (root.Has("shape")) root["shape"].Fail("only parametric avatars have a shape");
    return BuildTubeAvatar(params);
  }
  BodyShape shape;
  if (root.Has("shape")) {
    const JsonNode s = root["shape"];
    s.CheckKeys({"shoulder_width", "hip_width", "arm_length", "leg_length", "head_size", "belly", "clothing"});
    auto ratio = [&](const char* key, double& out, double lo, double hi) {
      if (!s.Has(key)) return;
      out = s.GetDouble(key);
      if (out < lo || out > hi) s[key].Fail("must be in " + std::to_string(lo).substr(0, 4) + ".." + std::to_string(hi).substr(0, 4));
    };
    ratio("shoulder_width", shape.shoulder_width, 0.8, 1.25);
    ratio("hip_width", shape.hip_width, 0.8, 1.3);
    ratio("arm_length", shape.arm_length, 0.85, 1.15);
    ratio("leg_length", shape.leg_length, 0.85, 1.15);
    ratio("head_size", shape.head_size, 0.85, 1.15);
    ratio("belly", shape.belly, 0.0, 1.0);
    shape.clothing = s.GetString("clothing", "tight");
    if (shape.clothing != "tight" && shape.clothing != "loose_shirt" && shape.clothing != "jacket") {
      s["clothing"].Fail("must be tight, loose_shirt or jacket");
    }
  }
  return BuildParametricAvatar(params, shape);
}

// Building a parametric avatar's mesh takes about 50 ms (a second under the
// sanitizers), and suites and sweeps load each avatar several times (to check
// a scenario, to key its render, to render it): parametric and tube avatars,
// made from their JSON alone, are kept once built, keyed by the file's name
// and parsed contents. Mesh avatars read a second file and are not kept.
class BuiltAvatars {
 public:
  static std::optional<Avatar> Find(const std::string& key) {
    std::lock_guard lock(mutex_);
    const auto it = built().find(key);
    if (it == built().end()) return std::nullopt;
    return it->second;
  }
  static void Keep(const std::string& key, const Avatar& avatar) {
    std::lock_guard lock(mutex_);
    if (built().size() >= 16) built().clear();
    built().emplace(key, avatar);
  }

 private:
  static std::map<std::string, Avatar>& built() {
    static std::map<std::string, Avatar> m;
    return m;
  }
  static inline std::mutex mutex_;
};

}  // namespace

Avatar LoadAvatar(const std::filesystem::path& path) {
  const std::string ext = LowerExtension(path);
  if (ext != ".json") {
    // A rigged mesh file itself, imported with the default options.
    ImportOptions options;
    return ImportRiggedAvatar(path, options);
  }
  const JsonNode root = ParseJsonFile(path.string());
  root.CheckKeys({"format", "name", "description", "kind", "height_m", "build", "albedo", "style", "shape",
                  "file", "scale", "up_axis", "joint_map"});
  if (root.GetString("format") != "irbench.avatar/1") root["format"].Fail("expected \"irbench.avatar/1\"");
  const std::string kind = root.GetString("kind");
  if (kind != "tube" && kind != "parametric" && kind != "mesh") {
    root["kind"].Fail("unknown avatar kind '" + kind + "' (tube, parametric, mesh)");
  }
  AvatarParams params;
  params.kind = kind;
  params.name = root.GetString("name", path.stem().string());
  if (root.Has("style")) {
    if (!root["style"].raw().is_object()) root["style"].Fail("must be an object (see docs/motion.md)");
    params.style = root["style"].raw();
  }
  if (kind == "mesh") return LoadMeshAvatar(path, root, params.name, params.style);
  const std::string key = path.stem().string() + '\n' + root.raw().dump();
  if (std::optional<Avatar> built = BuiltAvatars::Find(key)) return *std::move(built);
  Avatar avatar = BuildDescribedAvatar(root, params);
  BuiltAvatars::Keep(key, avatar);
  return avatar;
}

void SkinVertices(const Avatar& avatar,
                  const JointTransforms& world_from_joint,
                  std::vector<MeshVertex>& out) {
  // skin_from_bind per joint: world_from_joint * joint_from_bind, where the
  // bind frame of a joint is a pure translation to its bind position.
  std::array<Eigen::Matrix3f, kJointCount> rotation;
  std::array<Eigen::Vector3f, kJointCount> translation;
  for (int j = 0; j < kJointCount; ++j) {
    rotation[j] = world_from_joint[j].linear().cast<float>();
    translation[j] = (world_from_joint[j].translation() -
                      world_from_joint[j].linear() * avatar.skeleton.bind_position[j])
                         .cast<float>();
  }
  out.resize(avatar.bind_vertices.size());
  for (size_t i = 0; i < avatar.bind_vertices.size(); ++i) {
    const MeshVertex& v = avatar.bind_vertices[i];
    Eigen::Vector3f p = Eigen::Vector3f::Zero(), n = Eigen::Vector3f::Zero();
    for (int k = 0; k < 4; ++k) {
      const float w = avatar.bone_weight[i][k];
      if (w == 0.0f) continue;
      const int b = avatar.bone_index[i][k];
      p += w * (rotation[b] * v.position + translation[b]);
      n += w * (rotation[b] * v.normal);
    }
    out[i] = v;
    out[i].position = p;
    out[i].normal = n.normalized();
  }
}

const std::vector<std::string>& TruthJointNames() {
  static const std::vector<std::string> names = {
      "root",           "waist",          "neck",           "head",
      "left_shoulder",  "left_elbow",     "left_wrist",     "left_hand_tip",
      "right_shoulder", "right_elbow",    "right_wrist",    "right_hand_tip",
      "left_hip",       "left_knee",      "left_ankle",     "right_hip",
      "right_knee",     "right_ankle"};
  return names;
}

std::vector<Eigen::Vector3d> TruthJoints(const Avatar& avatar, const JointTransforms& world_from_joint) {
  auto joint = [&](int j) { return Eigen::Vector3d(world_from_joint[j].translation()); };
  auto marker = [&](const std::string& name) {
    for (const BoneMarker& m : avatar.markers) {
      if (m.name == name) return Eigen::Vector3d(world_from_joint[m.joint] * m.offset_in_joint);
    }
    return Eigen::Vector3d(Eigen::Vector3d::Constant(std::nan("")));
  };
  const Eigen::Vector3d mid_ankle = 0.5 * (joint(kLeftAnkle) + joint(kRightAnkle));
  return {Eigen::Vector3d(mid_ankle.x(), mid_ankle.y(), 0.0),
          joint(kSpine),
          joint(kNeck),
          marker("head"),
          joint(kLeftShoulder),
          joint(kLeftElbow),
          joint(kLeftWrist),
          marker("left_hand_tip"),
          joint(kRightShoulder),
          joint(kRightElbow),
          joint(kRightWrist),
          marker("right_hand_tip"),
          joint(kLeftHip),
          joint(kLeftKnee),
          joint(kLeftAnkle),
          joint(kRightHip),
          joint(kRightKnee),
          joint(kRightAnkle)};
}

}  // namespace irbench
