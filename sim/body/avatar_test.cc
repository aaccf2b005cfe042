#include "sim/body/avatar.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <map>

#include "common/error.h"

namespace irbench {
namespace {

TEST(AvatarTest, SkinningAtBindPoseReturnsTheBindMesh) {
  const Avatar avatar = BuildTubeAvatar({});
  std::vector<MeshVertex> skinned;
  SkinVertices(avatar, ForwardKinematics(avatar.skeleton, Pose()), skinned);
  ASSERT_EQ(skinned.size(), avatar.bind_vertices.size());
  for (size_t i = 0; i < skinned.size(); ++i) {
    EXPECT_LT((skinned[i].position - avatar.bind_vertices[i].position).norm(), 1e-5f);
  }
}

TEST(AvatarTest, WeightsAreNormalisedAndMeshIsClosedPerPart) {
  const Avatar avatar = BuildTubeAvatar({});
  EXPECT_GT(avatar.indices.size() / 3, 5000u);
  for (const auto& w : avatar.bone_weight) EXPECT_NEAR(w[0] + w[1] + w[2] + w[3], 1.0f, 1e-6f);
  // Each tube is closed: every undirected edge is shared by exactly two triangles.
  std::map<std::pair<uint32_t, uint32_t>, int> edges;
  for (size_t t = 0; t < avatar.indices.size(); t += 3) {
    for (int k = 0; k < 3; ++k) {
      uint32_t a = avatar.indices[t + k], b = avatar.indices[t + (k + 1) % 3];
      edges[{std::min(a, b), std::max(a, b)}]++;
    }
  }
  for (const auto& [edge, count] : edges) ASSERT_EQ(count, 2);
}

TEST(AvatarTest, TruthJointsAndHeight) {
  for (double height : {1.55, 1.75, 1.95}) {
    AvatarParams params;
    params.height_m = height;
    const Avatar avatar = BuildTubeAvatar(params);
    float top = 0, bottom = 10;
    for (const auto& v : avatar.bind_vertices) {
      top = std::max(top, v.position.z());
      bottom = std::min(bottom, v.position.z());
    }
    EXPECT_NEAR(top, height, 0.01 * height);
    EXPECT_NEAR(bottom, 0.0, 0.005);
    const auto joints = TruthJoints(avatar, ForwardKinematics(avatar.skeleton, Pose()));
    ASSERT_EQ(joints.size(), TruthJointNames().size());
    EXPECT_NEAR(joints[0].z(), 0.0, 1e-12);  // root on the floor
    // Hand tips at the ends of the outstretched arms.
    double max_x = 0;
    for (const auto& v : avatar.bind_vertices) max_x = std::max<double>(max_x, v.position.x());
    EXPECT_NEAR(joints[11].x(), max_x, 0.002 * height);  // right_hand_tip
  }
}

TEST(AvatarTest, BadHeightIsAnInputError) {
  const auto path = std::filesystem::temp_directory_path() / "irbench_bad_avatar.json";
  FILE* f = std::fopen(path.c_str(), "w");
  std::fputs(R"({"format": "irbench.avatar/1", "kind": "tube", "height_m": 2.6})", f);
  std::fclose(f);
  try {
    LoadAvatar(path);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "height_m");
  }
}

// LoadAvatar keeps a built parametric avatar: loading again gives the same
// mesh, and a file rewritten in place (or a copy under another name) is
// built from what it now says, errors included.
TEST(AvatarTest, ReloadingFollowsTheFileContents) {
  const auto dir = std::filesystem::temp_directory_path() / "irbench_avatar_reload";
  std::filesystem::create_directories(dir);
  const auto write = [&](const std::string& name, double height) {
    FILE* f = std::fopen((dir / name).c_str(), "w");
    std::fprintf(f, R"({"format": "irbench.avatar/1", "kind": "parametric", "height_m": %.2f})", height);
    std::fclose(f);
    return dir / name;
  };
  const auto span = [](const Avatar& a) {
    double lo = 1e9, hi = -1e9;
    for (const MeshVertex& v : a.bind_vertices) lo = std::min<double>(lo, v.position.z()), hi = std::max<double>(hi, v.position.z());
    return hi - lo;
  };
  const Avatar first = LoadAvatar(write("reload.json", 1.60));
  const Avatar again = LoadAvatar(dir / "reload.json");
  ASSERT_EQ(again.bind_vertices.size(), first.bind_vertices.size());
  for (size_t i = 0; i < first.bind_vertices.size(); ++i) {
    ASSERT_EQ(again.bind_vertices[i].position, first.bind_vertices[i].position) << i;
  }
  EXPECT_EQ(again.params.name, "reload");
  const Avatar taller = LoadAvatar(write("reload.json", 1.90));
  EXPECT_NEAR(span(taller) - span(first), 0.30, 0.02);
  const Avatar renamed = LoadAvatar(write("other.json", 1.60));
  EXPECT_EQ(renamed.params.name, "other");
  write("reload.json", 2.60);
  EXPECT_THROW(LoadAvatar(dir / "reload.json"), InputError);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace irbench
