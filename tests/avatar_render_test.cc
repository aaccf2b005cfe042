// Imported rigged meshes through the renderer: the three test avatars beside
// the checkout (../shared/data/avatars; skipped when absent) import, map every
// canonical upper-body joint, render in a fast motion with raised, crossed and
// hidden arms, and have every visible truth joint on their masks.

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "sim/body/avatar_import.h"
#include "sim/sequence/render_job.h"
#include "sequence_format/manifest.h"
#include "tests/glb_edit.h"
#include "tests/mask_check.h"
#include "tests/test_util.h"

namespace irbench {
namespace {
namespace fs = std::filesystem;
using irbench::testing::FreshTempDir;
using irbench::testing::ReadText;
using irbench::testing::WriteText;

fs::path SharedAvatars() { return fs::path(IRBENCH_SOURCE_DIR) / ".." / "shared" / "data" / "avatars"; }

struct SharedAvatar {
  const char* file;
  double scale;  // metres per file unit; 0: the file's own (glTF: metres)
};

// The Wizard is modelled 3.08 units tall: 0.6 m per unit makes a 1.85 m person.
const SharedAvatar kSharedAvatars[] = {{"CesiumMan.glb", 0}, {"rigged_figure.glb", 0}, {"Wizard.glb", 0.6}};

// Imports `mesh`, renders it in lab4 with the fast motion as a user would
// (an avatar file of kind "mesh" naming it) and checks every visible truth
// joint lies on its mask. Returns the imported avatar.
Avatar ImportRenderAndCheck(const fs::path& mesh, double scale, const fs::path& dir) {
  Avatar imported;
  EXPECT_NO_THROW({
    ImportOptions options;
    options.scale = scale;
    imported = ImportRiggedAvatar(mesh, options);
  }) << mesh;
  EXPECT_EQ(imported.params.kind, "mesh");
  EXPECT_GE(imported.params.height_m, 1.4) << mesh;
  EXPECT_LE(imported.params.height_m, 1.95) << mesh;

  const fs::path avatar_json = dir / (mesh.stem().string() + ".json");
  nlohmann::json j = {{"format", "irbench.avatar/1"}, {"kind", "mesh"}, {"file", mesh.string()}};
  if (scale > 0) j["scale"] = scale;
  WriteText(avatar_json, j.dump());
  RenderJobOptions options;
  options.rig = "lab4";
  options.avatar = avatar_json.string();
  options.motion = (dir / "fast.json").string();
  options.frames = 7;
  options.background_frames = 0;
  options.out = dir / mesh.stem();
  const fs::path seq = RunRenderJob(options);
  int visible = 0;
  std::string worst_at;
  std::map<std::string, double> per_joint;
  const double worst = irbench::testing::WorstVisibleJointOffMask(seq, &visible, &worst_at, &per_joint);
  double worst_inner = 0;  // every truth point but the hand tips
  for (const auto& [joint, d] : per_joint) {
    if (joint.find("hand_tip") != std::string::npos) continue;
    worst_inner = std::max(worst_inner, d);
    if (d > 0) std::printf("  %s: %s %.2f px off the mask\n", mesh.filename().c_str(), joint.c_str(), d);
  }
  std::printf("%s: %.3f m, %d visible truth joints; joint centres %.2f px off the mask, hand tips %.2f px (%s)\n",
              mesh.filename().c_str(), imported.params.height_m, visible, worst_inner, worst, worst_at.c_str());
  EXPECT_GT(visible, 100) << mesh;
  // Inside the mask, to the pixel: the pixel a truth point rounds to is a
  // mask pixel or touches one (points on the surface — the hand tips, the
  // Wizard's ankles, which its rig puts at the boots' soles — can round
  // outward).
  EXPECT_LE(worst, 1.5) << mesh << ": " << worst_at;
  const auto manifest = ReadManifest(seq).json;
  EXPECT_EQ(manifest["avatar"]["kind"], "mesh") << manifest["avatar"].dump();
  fs::remove_all(seq);
  return imported;
}

TEST(AvatarRenderTest, SharedAvatarsImportRenderAndKeepTruthOnTheirMasks) {
  if (!fs::is_directory(SharedAvatars())) GTEST_SKIP() << SharedAvatars() << " is not here";
  const fs::path dir = FreshTempDir("avatar_render");
  WriteText(dir / "fast.json", irbench::testing::FastMotionJson());
  for (const SharedAvatar& a : kSharedAvatars) {
    const fs::path mesh = SharedAvatars() / a.file;
    if (!fs::is_regular_file(mesh)) {
      ADD_FAILURE() << mesh << " missing while its folder is here";
      continue;
    }
    // Every canonical upper-body joint maps to a rig joint by the built-in tables.
    const Avatar imported = ImportRenderAndCheck(mesh, a.scale, dir);
    EXPECT_NE(imported.params.source.value("convention", ""), "hierarchy") << a.file;
  }
}

// Issue 28.5: CesiumMan with every joint renamed to a meaningless name and an
// unweighted IK helper bone added maps by its hierarchy, renders, and keeps
// every visible truth joint on its mask.
TEST(AvatarRenderTest, ARigNoTableKnowsMapsByItsHierarchyAndRenders) {
  const fs::path original = SharedAvatars() / "CesiumMan.glb";
  if (!fs::is_regular_file(original)) GTEST_SKIP() << original << " is not here";
  const fs::path dir = FreshTempDir("avatar_render_renamed");
  WriteText(dir / "fast.json", irbench::testing::FastMotionJson());
  irbench::testing::Glb glb = irbench::testing::ReadGlb(original);
  const auto renames = irbench::testing::RenameJointsMeaninglessly(glb);
  irbench::testing::AddHelperJoint(glb, renames.at("Skeleton_torso_joint_1"), "ik_pole");
  const fs::path mesh = dir / "renamed_cesium.glb";
  irbench::testing::WriteGlb(mesh, glb);
  const Avatar imported = ImportRenderAndCheck(mesh, 0, dir);
  EXPECT_EQ(imported.params.source.value("convention", ""), "hierarchy");
}

}  // namespace
}  // namespace irbench
