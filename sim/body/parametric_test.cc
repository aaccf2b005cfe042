#include "sim/body/parametric.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>

namespace irbench {
namespace {

// Each undirected edge and how many triangles use it, and whether its two uses
// run in opposite directions (consistent orientation).
struct EdgeCheck {
  size_t edges = 0, not_two = 0, same_direction = 0;
};

EdgeCheck CheckEdges(const std::vector<uint32_t>& indices) {
  std::map<std::pair<uint32_t, uint32_t>, std::pair<int, int>> uses;  // (forward, backward)
  for (size_t t = 0; t < indices.size(); t += 3) {
    for (int e = 0; e < 3; ++e) {
      const uint32_t a = indices[t + e], b = indices[t + (e + 1) % 3];
      auto& u = uses[{std::min(a, b), std::max(a, b)}];
      (a < b ? u.first : u.second)++;
    }
  }
  EdgeCheck c;
  c.edges = uses.size();
  for (const auto& [edge, u] : uses) {
    if (u.first + u.second != 2) ++c.not_two;
    if (u.first != 1 || u.second != 1) ++c.same_direction;
  }
  return c;
}

// Signed volume of the triangles (all of them, or those whose three vertices
// satisfy `in`), as tetrahedra to `origin`.
double Volume(const std::vector<MeshVertex>& v, const std::vector<uint32_t>& idx, const Eigen::Vector3f& origin,
              const std::vector<bool>& in = {}) {
  double vol = 0;
  for (size_t t = 0; t < idx.size(); t += 3) {
    if (!in.empty() && !(in[idx[t]] && in[idx[t + 1]] && in[idx[t + 2]])) continue;
    const Eigen::Vector3f a = v[idx[t]].position - origin, b = v[idx[t + 1]].position - origin,
                          c = v[idx[t + 2]].position - origin;
    vol += a.dot(b.cross(c)) / 6.0;
  }
  return vol;
}

struct Person {
  double height, build;
  BodyShape shape;
};

const std::vector<Person>& Persons() {
  static const std::vector<Person> persons = [] {
    std::vector<Person> p(4);
    p[0] = {1.50, 0.8, {}};
    p[1] = {1.75, 1.0, {}};
    p[2] = {1.95, 1.3, {}};
    p[2].shape.belly = 0.5;
    p[3] = {1.68, 1.1, {}};
    p[3].shape.clothing = "jacket";
    p[3].shape.shoulder_width = 1.1;
    return p;
  }();
  return persons;
}

TEST(ParametricTest, WatertightManifoldAndHeightWithinOneCentimetre) {
  for (const Person& person : Persons()) {
    AvatarParams params;
    params.height_m = person.height;
    params.build = person.build;
    const Avatar a = BuildParametricAvatar(params, person.shape);
    const size_t triangles = a.indices.size() / 3;
    EXPECT_GE(triangles, 10000u);
    const EdgeCheck edges = CheckEdges(a.indices);
    EXPECT_EQ(edges.not_two, 0u) << person.height;         // every edge shared by exactly two faces
    EXPECT_EQ(edges.same_direction, 0u) << person.height;  // consistently oriented
    float top = -1e9f, bottom = 1e9f;
    for (const MeshVertex& v : a.bind_vertices) {
      top = std::max(top, v.position.z());
      bottom = std::min(bottom, v.position.z());
      ASSERT_TRUE(v.position.allFinite() && v.normal.allFinite());
    }
    EXPECT_NEAR(top - bottom, person.height, 0.01);
    EXPECT_NEAR(bottom, 0.0, 0.005);
    // Outward orientation: positive enclosed volume, of a plausible size: at
    // about 1000 kg/m^3, a body-mass index (kg/m^2) between 14 and 45.
    const double volume = Volume(a.bind_vertices, a.indices, Eigen::Vector3f::Zero());
    const double bmi = volume * 1000 / (person.height * person.height);
    EXPECT_GT(bmi, 14) << person.height;
    EXPECT_LT(bmi, 45) << person.height;
    // Weights: sum to one.
    for (const auto& w : a.bone_weight) ASSERT_NEAR(w[0] + w[1] + w[2] + w[3], 1.0f, 1e-5f);
    std::printf("h %.2f build %.2f %s: %zu triangles, %zu vertices, height %.4f m, volume %.1f l (BMI %.1f)\n",
                person.height, person.build, person.shape.clothing.c_str(), triangles, a.bind_vertices.size(),
                top - bottom, volume * 1000, bmi);
  }
}

// No candy-wrapper collapse: the arm region keeps its volume within 15% at
// 120° elbow flexion and at 150° shoulder abduction.
TEST(ParametricTest, ArmVolumeKeptUnderFlexionAndAbduction) {
  for (const Person& person : Persons()) {
    AvatarParams params;
    params.height_m = person.height;
    params.build = person.build;
    const Avatar a = BuildParametricAvatar(params, person.shape);
    std::vector<bool> in_arm(a.bind_vertices.size());
    for (size_t v = 0; v < in_arm.size(); ++v) {
      float w = 0;
      for (int k = 0; k < 4; ++k) {
        const int bone = a.bone_index[v][k];
        if (bone == kRightShoulder || bone == kRightElbow || bone == kRightWrist) w += a.bone_weight[v][k];
      }
      in_arm[v] = w >= 0.5f;
    }
    const Eigen::Vector3f shoulder = a.skeleton.bind_position[kRightShoulder].cast<float>();
    const double rest = Volume(a.bind_vertices, a.indices, shoulder, in_arm);
    ASSERT_GT(rest, 0.001);
    struct Case {
      const char* name;
      Pose pose;
    };
    Case flex{"elbow 120", {}}, abduct{"abduction 150", {}}, both{"both", {}};
    flex.pose.local_rotation[kRightElbow] = Eigen::AngleAxisd(120 * M_PI / 180, Eigen::Vector3d::UnitZ());
    // The T-pose is 90° of abduction; 60° more lifts the arm above the shoulder.
    abduct.pose.local_rotation[kRightShoulder] = Eigen::AngleAxisd(-60 * M_PI / 180, Eigen::Vector3d::UnitY());
    both.pose.local_rotation[kRightShoulder] = abduct.pose.local_rotation[kRightShoulder];
    both.pose.local_rotation[kRightElbow] = flex.pose.local_rotation[kRightElbow];
    for (const Case& c : {flex, abduct, both}) {
      std::vector<MeshVertex> posed;
      SkinVertices(a, ForwardKinematics(a.skeleton, c.pose), posed);
      const double v = Volume(posed, a.indices, shoulder, in_arm);
      EXPECT_NEAR(v / rest, 1.0, 0.15) << c.name << " h " << person.height;
      std::printf("h %.2f %s: arm region %.2f l, posed/rest %.3f\n", person.height, c.name, rest * 1000, v / rest);
    }
  }
}

// Every person shipped in avatars/: closed, and as tall as its parameter.
TEST(ParametricTest, ShippedPersonsAreWatertightAndTheirHeight) {
  int persons = 0, loose = 0;
  double lowest = 1e9, highest = 0, slimmest = 1e9, heaviest = 0;
  for (const auto& e : std::filesystem::directory_iterator(std::string(IRBENCH_SOURCE_DIR) + "/avatars")) {
    const Avatar a = LoadAvatar(e.path());
    if (a.params.kind != "parametric") continue;
    ++persons;
    EXPECT_EQ(CheckEdges(a.indices).not_two, 0u) << e.path();
    EXPECT_GE(a.indices.size() / 3, 10000u) << e.path();
    float top = -1e9f, bottom = 1e9f;
    for (const MeshVertex& v : a.bind_vertices) {
      top = std::max(top, v.position.z());
      bottom = std::min(bottom, v.position.z());
    }
    EXPECT_NEAR(top - bottom, a.params.height_m, 0.01) << e.path();
    lowest = std::min(lowest, a.params.height_m);
    highest = std::max(highest, a.params.height_m);
    slimmest = std::min(slimmest, a.params.build);
    heaviest = std::max(heaviest, a.params.build);
    std::ifstream in(e.path());
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    loose += text.find("loose_shirt") != std::string::npos || text.find("jacket") != std::string::npos;
  }
  EXPECT_GE(persons, 8);
  EXPECT_GE(loose, 2);
  EXPECT_LE(lowest, 1.52);
  EXPECT_GE(highest, 1.93);
  EXPECT_LE(slimmest, 0.85);
  EXPECT_GE(heaviest, 1.25);
}

}  // namespace
}  // namespace irbench
