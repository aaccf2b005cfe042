// Imported rigged meshes through the renderer: the three test avatars beside
// the checkout (../shared/data/avatars; skipped when absent) import, map every
// canonical upper-body joint, render in a fast motion with raised, crossed and
// hidden arms, and have every visible truth joint on their masks.

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "sim/body/avatar_import.h"
#include "sim/sequence/render_job.h"
#include "sequence_format/manifest.h"
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
    Avatar imported;
    ASSERT_NO_THROW({
      ImportOptions options;
      options.scale = a.scale;
      imported = ImportRiggedAvatar(mesh, options);
    }) << a.file;
    EXPECT_EQ(imported.params.kind, "mesh");
    EXPECT_GE(imported.params.height_m, 1.4) << a.file;
    EXPECT_LE(imported.params.height_m, 1.95) << a.file;

    // Rendered as a user would: an avatar file of kind "mesh" naming the mesh.
    const fs::path avatar_json = dir / (mesh.stem().string() + ".json");
    nlohmann::json j = {{"format", "irbench.avatar/1"}, {"kind", "mesh"}, {"file", mesh.string()}};
    if (a.scale > 0) j["scale"] = a.scale;
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
      if (d > 0) std::printf("  %s: %s %.2f px off the mask\n", a.file, joint.c_str(), d);
    }
    std::printf("%s: %.3f m, %d visible truth joints; joint centres %.2f px off the mask, hand tips %.2f px (%s)\n",
                a.file, imported.params.height_m, visible, worst_inner, worst, worst_at.c_str());
    EXPECT_GT(visible, 100) << a.file;
    // Inside the mask, to the pixel: the pixel a truth point rounds to is a
    // mask pixel or touches one (points on the surface — the hand tips, the
    // Wizard's ankles, which its rig puts at the boots' soles — can round
    // outward).
    EXPECT_LE(worst, 1.5) << a.file << ": " << worst_at;
    const auto manifest = ReadManifest(seq).json;
    EXPECT_EQ(manifest["avatar"]["kind"], "mesh") << manifest["avatar"].dump();
    fs::remove_all(seq);
  }
}

}  // namespace
}  // namespace irbench
