#include "sim/body/avatar_import.h"

#include <assimp/scene.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <assimp/Exporter.hpp>
#include <assimp/Importer.hpp>
#include <cmath>
#include <cstring>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <random>
#include <set>
#include <string>

#include "common/error.h"
#include "sim/body/gltf_export.h"
#include "sim/body/parametric.h"
#include "tests/glb_edit.h"

namespace irbench {
namespace {

namespace fs = std::filesystem;
using irbench::testing::AddHelperJoint;
using irbench::testing::Glb;
using irbench::testing::MoveWeights;
using irbench::testing::ReadGlb;
using irbench::testing::RenameJointsMeaninglessly;
using irbench::testing::RenameNodes;
using irbench::testing::WriteGlb;

// ---------------------------------------------------------------------------
// Joint-name tables.

std::vector<std::string> Sided(const std::vector<std::string>& names,
                               const std::string& left,
                               const std::string& right,
                               bool prefix) {
  std::vector<std::string> out;
  for (const std::string& n : names) {
    out.push_back(prefix ? left + n : n + left);
    out.push_back(prefix ? right + n : n + right);
  }
  return out;
}

// Expects `map` to hold exactly these canonical -> rig pairs (among others).
void ExpectMapped(const JointMapping& m, const std::map<std::string, std::string>& expected) {
  for (const auto& [canonical, rig] : expected) {
    const auto it = m.map.find(canonical);
    ASSERT_NE(it, m.map.end()) << canonical << " unmapped (convention " << m.convention << ")";
    EXPECT_EQ(it->second, rig) << canonical;
  }
}

TEST(MapRigJointsTest, Mixamo) {
  std::vector<std::string> names = {"mixamorig:Hips",       "mixamorig:Spine", "mixamorig:Spine1",
                                    "mixamorig:Spine2",     "mixamorig:Neck",  "mixamorig:Head",
                                    "mixamorig:HeadTop_End"};
  for (const std::string& n : Sided({"Shoulder", "Arm", "ForeArm", "Hand", "HandIndex1",
                                     "HandThumb1", "UpLeg", "Leg", "Foot", "ToeBase"},
                                    "mixamorig:Left", "mixamorig:Right", true)) {
    names.push_back(n);
  }
  const JointMapping m = MapRigJoints(names, {});
  EXPECT_EQ(m.convention, "mixamo");
  ExpectMapped(m, {{"pelvis", "mixamorig:Hips"},
                   {"spine", "mixamorig:Spine"},
                   {"chest", "mixamorig:Spine2"},
                   {"neck", "mixamorig:Neck"},
                   {"head", "mixamorig:Head"},
                   {"right_clavicle", "mixamorig:RightShoulder"},
                   {"right_shoulder", "mixamorig:RightArm"},
                   {"right_elbow", "mixamorig:RightForeArm"},
                   {"right_wrist", "mixamorig:RightHand"},
                   {"left_clavicle", "mixamorig:LeftShoulder"},
                   {"left_shoulder", "mixamorig:LeftArm"},
                   {"left_elbow", "mixamorig:LeftForeArm"},
                   {"left_wrist", "mixamorig:LeftHand"},
                   {"right_hip", "mixamorig:RightUpLeg"},
                   {"right_knee", "mixamorig:RightLeg"},
                   {"right_ankle", "mixamorig:RightFoot"},
                   {"left_hip", "mixamorig:LeftUpLeg"},
                   {"left_knee", "mixamorig:LeftLeg"},
                   {"left_ankle", "mixamorig:LeftFoot"}});
  EXPECT_EQ(m.map.size(), 19u);
  // Unmapped: Spine1, HeadTop_End, fingers and toes.
  EXPECT_EQ(m.unmapped_rig_joints.size(), names.size() - 19);
}

TEST(MapRigJointsTest, Rigify) {
  std::vector<std::string> names = {"DEF-spine",     "DEF-spine.001", "DEF-spine.002",
                                    "DEF-spine.003", "DEF-spine.004", "DEF-spine.005",
                                    "DEF-spine.006"};
  for (const char* side : {".L", ".R"}) {
    for (const char* bone : {"DEF-shoulder", "DEF-upper_arm", "DEF-forearm", "DEF-hand",
                             "DEF-thigh", "DEF-shin", "DEF-foot", "DEF-toe"}) {
      names.push_back(std::string(bone) + side);
    }
    // Rigify's twist segments.
    for (const char* bone : {"DEF-upper_arm", "DEF-forearm", "DEF-thigh", "DEF-shin"}) {
      names.push_back(std::string(bone) + side + ".001");
    }
  }
  const JointMapping m = MapRigJoints(names, {});
  EXPECT_EQ(m.convention, "rigify");
  ExpectMapped(m, {{"pelvis", "DEF-spine"},
                   {"spine", "DEF-spine.001"},
                   {"chest", "DEF-spine.002"},
                   {"neck", "DEF-spine.004"},
                   {"head", "DEF-spine.006"},
                   {"right_clavicle", "DEF-shoulder.R"},
                   {"right_shoulder", "DEF-upper_arm.R"},
                   {"right_elbow", "DEF-forearm.R"},
                   {"right_wrist", "DEF-hand.R"},
                   {"left_clavicle", "DEF-shoulder.L"},
                   {"left_shoulder", "DEF-upper_arm.L"},
                   {"left_elbow", "DEF-forearm.L"},
                   {"left_wrist", "DEF-hand.L"},
                   {"left_hip", "DEF-thigh.L"},
                   {"left_knee", "DEF-shin.L"},
                   {"left_ankle", "DEF-foot.L"}});
}

TEST(MapRigJointsTest, BlenderMetarigIsGeneric) {
  std::vector<std::string> names = {"hips", "spine", "chest", "neck", "head"};
  for (const std::string& n :
       Sided({"shoulder", "upper_arm", "forearm", "hand", "thigh", "shin", "foot"}, ".L", ".R",
             false)) {
    names.push_back(n);
  }
  const JointMapping m = MapRigJoints(names, {});
  EXPECT_EQ(m.convention, "generic");
  ExpectMapped(m, {{"pelvis", "hips"},
                   {"spine", "spine"},
                   {"chest", "chest"},
                   {"neck", "neck"},
                   {"head", "head"},
                   {"left_clavicle", "shoulder.L"},
                   {"left_shoulder", "upper_arm.L"},
                   {"left_elbow", "forearm.L"},
                   {"left_wrist", "hand.L"},
                   {"right_shoulder", "upper_arm.R"},
                   {"right_elbow", "forearm.R"},
                   {"right_wrist", "hand.R"},
                   {"right_knee", "shin.R"}});
}

TEST(MapRigJointsTest, MakeHumanDefaultAndGameEngine) {
  std::vector<std::string> names = {"root",   "spine05", "spine04", "spine03", "spine02", "spine01",
                                    "neck01", "neck02",  "neck03",  "head",    "jaw"};
  for (const std::string& n :
       Sided({"clavicle", "shoulder01", "upperarm01", "upperarm02", "lowerarm01", "lowerarm02",
              "wrist", "pelvis", "upperleg01", "upperleg02", "lowerleg01", "lowerleg02", "foot"},
             ".L", ".R", false)) {
    names.push_back(n);
  }
  const JointMapping m = MapRigJoints(names, {});
  EXPECT_EQ(m.convention, "makehuman");
  ExpectMapped(m, {{"pelvis", "root"},
                   {"spine", "spine05"},
                   {"chest", "spine03"},
                   {"neck", "neck01"},
                   {"head", "head"},
                   {"left_clavicle", "clavicle.L"},
                   {"left_shoulder", "upperarm01.L"},
                   {"left_elbow", "lowerarm01.L"},
                   {"left_wrist", "wrist.L"},
                   {"right_shoulder", "upperarm01.R"},
                   {"right_elbow", "lowerarm01.R"},
                   {"right_wrist", "wrist.R"},
                   {"right_hip", "upperleg01.R"},
                   {"right_knee", "lowerleg01.R"},
                   {"right_ankle", "foot.R"}});

  std::vector<std::string> game = {"pelvis", "spine_01", "spine_02", "spine_03", "neck_01", "head"};
  for (const std::string& n :
       Sided({"clavicle", "upperarm", "lowerarm", "hand", "thigh", "calf", "foot", "ball"}, "_l",
             "_r", false)) {
    game.push_back(n);
  }
  const JointMapping g = MapRigJoints(game, {});
  EXPECT_EQ(g.convention, "unreal");
  ExpectMapped(g, {{"pelvis", "pelvis"},
                   {"spine", "spine_01"},
                   {"chest", "spine_03"},
                   {"neck", "neck_01"},
                   {"head", "head"},
                   {"right_shoulder", "upperarm_r"},
                   {"right_elbow", "lowerarm_r"},
                   {"right_wrist", "hand_r"},
                   {"left_shoulder", "upperarm_l"},
                   {"left_elbow", "lowerarm_l"},
                   {"left_wrist", "hand_l"},
                   {"left_knee", "calf_l"}});
}

const std::vector<std::string> kWizardJoints = {
    "Root",       "Foot.L",      "Body",       "Hips",       "Abdomen",    "Torso",
    "Neck",       "Head",        "Shoulder.L", "UpperArm.L", "LowerArm.L", "Fist.L",
    "Fist1.L",    "Fist2.L",     "Thumb1.L",   "Thumb2.L",   "Shoulder.R", "UpperArm.R",
    "LowerArm.R", "Fist.R",      "Fist1.R",    "Fist2.R",    "Weapon.R",   "Thumb1.R",
    "Thumb2.R",   "UpperLeg.L",  "LowerLeg.L", "UpperLeg.R", "LowerLeg.R", "PoleTarget.L",
    "Foot.R",     "PoleTarget.R"};

TEST(MapRigJointsTest, Wizard) {
  const JointMapping m = MapRigJoints(kWizardJoints, {});
  EXPECT_EQ(m.convention, "generic");
  ExpectMapped(m, {{"pelvis", "Hips"},
                   {"spine", "Abdomen"},
                   {"chest", "Torso"},
                   {"neck", "Neck"},
                   {"head", "Head"},
                   {"right_clavicle", "Shoulder.R"},
                   {"right_shoulder", "UpperArm.R"},
                   {"right_elbow", "LowerArm.R"},
                   {"right_wrist", "Fist.R"},
                   {"left_clavicle", "Shoulder.L"},
                   {"left_shoulder", "UpperArm.L"},
                   {"left_elbow", "LowerArm.L"},
                   {"left_wrist", "Fist.L"},
                   {"right_hip", "UpperLeg.R"},
                   {"right_knee", "LowerLeg.R"},
                   {"right_ankle", "Foot.R"},
                   {"left_hip", "UpperLeg.L"},
                   {"left_knee", "LowerLeg.L"},
                   {"left_ankle", "Foot.L"}});
}

TEST(MapRigJointsTest, CesiumManAndRiggedFigure) {
  // CesiumMan numbers its two arms differently (verified on the joint
  // positions: L__4_ -> L__3_ -> L__2_ and R -> R__2_ -> R__3_ run outwards).
  const std::vector<std::string> cesium_man = {"Skeleton_torso_joint_1",
                                               "Skeleton_torso_joint_2",
                                               "torso_joint_3",
                                               "Skeleton_neck_joint_1",
                                               "Skeleton_neck_joint_2",
                                               "Skeleton_arm_joint_L__4_",
                                               "Skeleton_arm_joint_R",
                                               "Skeleton_arm_joint_L__3_",
                                               "Skeleton_arm_joint_R__2_",
                                               "Skeleton_arm_joint_L__2_",
                                               "Skeleton_arm_joint_R__3_",
                                               "leg_joint_L_1",
                                               "leg_joint_R_1",
                                               "leg_joint_L_2",
                                               "leg_joint_R_2",
                                               "leg_joint_L_3",
                                               "leg_joint_R_3",
                                               "leg_joint_L_5",
                                               "leg_joint_R_5"};
  const JointMapping m = MapRigJoints(cesium_man, {});
  EXPECT_EQ(m.convention, "cesium");
  ExpectMapped(m, {{"pelvis", "Skeleton_torso_joint_1"},
                   {"spine", "Skeleton_torso_joint_2"},
                   {"chest", "torso_joint_3"},
                   {"neck", "Skeleton_neck_joint_1"},
                   {"head", "Skeleton_neck_joint_2"},
                   {"left_shoulder", "Skeleton_arm_joint_L__4_"},
                   {"left_elbow", "Skeleton_arm_joint_L__3_"},
                   {"left_wrist", "Skeleton_arm_joint_L__2_"},
                   {"right_shoulder", "Skeleton_arm_joint_R"},
                   {"right_elbow", "Skeleton_arm_joint_R__2_"},
                   {"right_wrist", "Skeleton_arm_joint_R__3_"},
                   {"left_hip", "leg_joint_L_1"},
                   {"left_knee", "leg_joint_L_2"},
                   {"left_ankle", "leg_joint_L_3"},
                   {"right_ankle", "leg_joint_R_3"}});
  EXPECT_EQ(m.map.count("left_clavicle"), 0u);

  const std::vector<std::string> figure = {
      "torso_joint_1", "torso_joint_2", "torso_joint_3", "neck_joint_1",  "neck_joint_2",
      "arm_joint_L_1", "arm_joint_R_1", "arm_joint_L_2", "arm_joint_R_2", "arm_joint_L_3",
      "arm_joint_R_3", "leg_joint_L_1", "leg_joint_R_1", "leg_joint_L_2", "leg_joint_R_2",
      "leg_joint_L_3", "leg_joint_R_3", "leg_joint_L_5", "leg_joint_R_5"};
  const JointMapping f = MapRigJoints(figure, {});
  EXPECT_EQ(f.convention, "cesium");
  ExpectMapped(f, {{"pelvis", "torso_joint_1"},
                   {"neck", "neck_joint_1"},
                   {"head", "neck_joint_2"},
                   {"left_shoulder", "arm_joint_L_1"},
                   {"left_elbow", "arm_joint_L_2"},
                   {"left_wrist", "arm_joint_L_3"},
                   {"right_shoulder", "arm_joint_R_1"},
                   {"right_elbow", "arm_joint_R_2"},
                   {"right_wrist", "arm_joint_R_3"},
                   {"right_hip", "leg_joint_R_1"}});
  EXPECT_EQ(f.unmapped_rig_joints, (std::vector<std::string>{"leg_joint_L_5", "leg_joint_R_5"}));
}

TEST(MapRigJointsTest, OverridesWinAndAreChecked) {
  const JointMapping m =
      MapRigJoints(kWizardJoints, {{"right_wrist", "fist1.r"}, {"left_clavicle", ""}});
  EXPECT_EQ(m.map.at("right_wrist"), "Fist1.R");
  EXPECT_EQ(m.map.count("left_clavicle"), 0u);
  // The override takes the rig joint from the table's choice.
  const JointMapping n = MapRigJoints(kWizardJoints, {{"right_elbow", "Fist.R"}});
  EXPECT_EQ(n.map.at("right_elbow"), "Fist.R");
  EXPECT_EQ(n.map.count("right_wrist"), 0u);
  try {
    MapRigJoints(kWizardJoints, {{"right_hand", "Fist.R"}});
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "joint_map.right_hand");
  }
  try {
    MapRigJoints(kWizardJoints, {{"right_wrist", "Paw.R"}});
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "joint_map.right_wrist");
  }
  EXPECT_EQ(MapRigJoints({"a", "b"}, {}).convention, "unknown");
}

// ---------------------------------------------------------------------------
// Importing the test avatars.

fs::path AvatarDir() {
  return fs::path(IRBENCH_SOURCE_DIR) / ".." / "shared" / "data" / "avatars";
}

fs::path TempDir() {
  const fs::path dir =
      fs::temp_directory_path() / ("irbench_import_test_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  return dir;
}

// The field of the InputError `f` throws.
template <class F>
std::string ErrorField(F&& f, std::string* message = nullptr) {
  try {
    f();
  } catch (const InputError& e) {
    if (message) *message = e.what();
    return e.field();
  }
  return "(no InputError)";
}

double AngleDeg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::acos(std::clamp(a.normalized().dot(b.normalized()), -1.0, 1.0)) * 180.0 / M_PI;
}

struct Case {
  const char* file;
  double scale;
  double expected_height;  // metres
};

// Expected heights: CesiumMan and rigged_figure from SOURCE.md (bind pose,
// skinned, metres). Wizard: 3.078 file units = the bind-pose vertical extent of
// the skinned body plus the rigid meshes the importer keeps (Face on Head,
// shoulder pads, pouch; not the staff), y from -0.0033 to 3.0747, measured with
// a separate Python script reading the GLB's JSON and BIN chunks (raw skinned
// positions; rigid meshes placed by their joint's inverse bind matrix), at the
// 0.6 m per unit the test imports it with.
const Case kCases[] = {
    {"CesiumMan.glb", 0, 1.507}, {"rigged_figure.glb", 0, 1.450}, {"Wizard.glb", 0.6, 0.6 * 3.078}};

class ImportTest : public ::testing::TestWithParam<Case> {};

TEST_P(ImportTest, StandsInTheCanonicalTPose) {
  const Case c = GetParam();
  const fs::path file = AvatarDir() / c.file;
  if (!fs::exists(file)) GTEST_SKIP() << file << " is not here";
  ImportOptions options;
  options.scale = c.scale;
  Avatar avatar;
  ASSERT_NO_THROW(avatar = ImportRiggedAvatar(file, options));
  const auto& b = avatar.skeleton.bind_position;
  const double h = avatar.params.height_m;
  EXPECT_EQ(avatar.params.name, file.stem().string());
  EXPECT_EQ(avatar.params.build, 1.0);
  EXPECT_GE(h, 1.0);
  EXPECT_LE(h, 2.3);
  EXPECT_NEAR(h, c.expected_height, 0.03);

  // Mesh: finite, on the floor, as tall as the parameters say.
  ASSERT_FALSE(avatar.bind_vertices.empty());
  ASSERT_EQ(avatar.indices.size() % 3, 0u);
  for (uint32_t i : avatar.indices) ASSERT_LT(i, avatar.bind_vertices.size());
  double lo = 1e9, hi = -1e9;
  size_t max_x = 0, min_x = 0;
  for (size_t i = 0; i < avatar.bind_vertices.size(); ++i) {
    const MeshVertex& v = avatar.bind_vertices[i];
    ASSERT_TRUE(v.position.allFinite()) << i;
    ASSERT_TRUE(v.normal.allFinite()) << i;
    EXPECT_NEAR(v.normal.norm(), 1.0f, 1e-4f);
    EXPECT_GE(v.albedo, 0.0f);
    EXPECT_LE(v.albedo, 1.0f);
    EXPECT_EQ(v.emissive, 0.0f);
    lo = std::min<double>(lo, v.position.z());
    hi = std::max<double>(hi, v.position.z());
    if (v.position.x() > avatar.bind_vertices[max_x].position.x()) max_x = i;
    if (v.position.x() < avatar.bind_vertices[min_x].position.x()) min_x = i;
  }
  EXPECT_NEAR(lo, 0.0, 1e-5);
  EXPECT_NEAR(hi, h, 1e-5);
  EXPECT_NEAR(b[kPelvis].x(), 0.0, 1e-9);
  EXPECT_NEAR(b[kPelvis].y(), 0.0, 1e-9);

  // Weights.
  ASSERT_EQ(avatar.bone_weight.size(), avatar.bind_vertices.size());
  ASSERT_EQ(avatar.bone_index.size(), avatar.bind_vertices.size());
  for (size_t i = 0; i < avatar.bone_weight.size(); ++i) {
    const auto& w = avatar.bone_weight[i];
    EXPECT_NEAR(w[0] + w[1] + w[2] + w[3], 1.0f, 1e-5f) << i;
    for (int k = 0; k < 4; ++k) {
      EXPECT_GE(w[k], 0.0f);
      EXPECT_LT(avatar.bone_index[i][k], kJointCount);
    }
  }

  // T-pose.
  for (const auto& [shoulder, sign] :
       {std::pair{kRightShoulder, 1.0}, std::pair{kLeftShoulder, -1.0}}) {
    const Eigen::Vector3d x(sign, 0, 0);
    const double upper = AngleDeg(b[shoulder + 1] - b[shoulder], x);
    const double fore = AngleDeg(b[shoulder + 2] - b[shoulder + 1], x);
    EXPECT_LT(upper, 3.0) << JointName(shoulder);
    EXPECT_LT(fore, 3.0) << JointName(shoulder);
  }
  for (int hip : {kRightHip, kLeftHip}) {
    const Eigen::Vector3d down(0, 0, -1);
    EXPECT_LT(AngleDeg(b[hip + 1] - b[hip], down), 5.0) << JointName(hip);
    EXPECT_LT(AngleDeg(b[hip + 2] - b[hip + 1], down), 5.0) << JointName(hip);
  }
  EXPECT_LT(AngleDeg(b[kNeck] - b[kChest], Eigen::Vector3d::UnitZ()), 3.0);
  EXPECT_GT(b[kRightShoulder].x(), 0.05);
  EXPECT_LT(b[kLeftShoulder].x(), -0.05);
  EXPECT_GT(b[kRightHip].x(), 0.0);
  EXPECT_LT(b[kLeftHip].x(), 0.0);
  // Seen on the mesh alone: the outermost vertices are the hands, level with
  // the shoulders (an A-pose would put them 0.2-0.4 m lower), beyond the wrists.
  const Eigen::Vector3d right_end = avatar.bind_vertices[max_x].position.cast<double>();
  const Eigen::Vector3d left_end = avatar.bind_vertices[min_x].position.cast<double>();
  EXPECT_NEAR(right_end.z(), b[kRightShoulder].z(), 0.06 * h);
  EXPECT_NEAR(left_end.z(), b[kLeftShoulder].z(), 0.06 * h);
  EXPECT_GT(right_end.x(), b[kRightWrist].x());
  EXPECT_LT(left_end.x(), b[kLeftWrist].x());
  // Facing +y: the soles reach further forward than back from the ankles.
  double sole_front = -1e9, sole_back = 1e9;
  for (const MeshVertex& v : avatar.bind_vertices) {
    if (v.position.z() > 0.03 * h) continue;
    sole_front = std::max<double>(sole_front, v.position.y());
    sole_back = std::min<double>(sole_back, v.position.y());
  }
  const double ankle_y = 0.5 * (b[kRightAnkle].y() + b[kLeftAnkle].y());
  EXPECT_GT(sole_front - ankle_y, ankle_y - sole_back);

  // Markers and radii.
  const JointTransforms bind = ForwardKinematics(avatar.skeleton, Pose());
  const auto truth = TruthJoints(avatar, bind);
  const auto& names = TruthJointNames();
  for (size_t i = 0; i < truth.size(); ++i) EXPECT_TRUE(truth[i].allFinite()) << names[i];
  EXPECT_GT(truth[3].z(), truth[2].z());                // head above the neck
  EXPECT_GT(truth[11].x(), b[kRightWrist].x() + 0.02);  // right hand tip beyond the wrist
  EXPECT_NEAR(truth[11].x(), right_end.x(), 0.01);      // ... at the end of the hand
  EXPECT_LT(truth[7].x(), b[kLeftWrist].x() - 0.02);
  for (const char* key : {"root", "waist", "neck", "head", "shoulder", "elbow", "wrist", "hand_tip",
                          "hip", "knee", "ankle"}) {
    ASSERT_TRUE(avatar.truth_radius.count(key)) << key;
    EXPECT_GE(avatar.truth_radius.at(key), 0.0) << key;
    EXPECT_LT(avatar.truth_radius.at(key), 0.3) << key;
  }

  // Identity pose reproduces the bind mesh.
  std::vector<MeshVertex> skinned;
  SkinVertices(avatar, bind, skinned);
  ASSERT_EQ(skinned.size(), avatar.bind_vertices.size());
  double worst = 0;
  for (size_t i = 0; i < skinned.size(); ++i) {
    worst =
        std::max<double>(worst, (skinned[i].position - avatar.bind_vertices[i].position).norm());
  }
  EXPECT_LT(worst, 1e-5);

  // Bending the right elbow moves the right hand only.
  Pose pose;
  pose.local_rotation[kRightElbow] = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ());
  SkinVertices(avatar, ForwardKinematics(avatar.skeleton, pose), skinned);
  EXPECT_GT((skinned[max_x].position - avatar.bind_vertices[max_x].position).norm(), 0.1);
  EXPECT_LT((skinned[min_x].position - avatar.bind_vertices[min_x].position).norm(), 1e-5);

  std::printf(
      "%s: height %.3f m, %zu vertices, %zu triangles; shoulders %.3f apart at z %.3f, wrists x "
      "%.3f/%.3f, "
      "hand tips x %.3f/%.3f, head %.3f; radii waist %.3f neck %.3f head %.3f shoulder %.3f elbow "
      "%.3f "
      "wrist %.3f hand_tip %.3f hip %.3f knee %.3f ankle %.3f\n",
      c.file, h, avatar.bind_vertices.size(), avatar.indices.size() / 3,
      (b[kRightShoulder] - b[kLeftShoulder]).norm(), b[kRightShoulder].z(), b[kRightWrist].x(),
      b[kLeftWrist].x(), truth[11].x(), truth[7].x(), truth[3].z(), avatar.truth_radius.at("waist"),
      avatar.truth_radius.at("neck"), avatar.truth_radius.at("head"),
      avatar.truth_radius.at("shoulder"), avatar.truth_radius.at("elbow"),
      avatar.truth_radius.at("wrist"), avatar.truth_radius.at("hand_tip"),
      avatar.truth_radius.at("hip"), avatar.truth_radius.at("knee"),
      avatar.truth_radius.at("ankle"));
}

INSTANTIATE_TEST_SUITE_P(Avatars,
                         ImportTest,
                         ::testing::ValuesIn(kCases),
                         [](const ::testing::TestParamInfo<Case>& info) {
                           std::string s = fs::path(info.param.file).stem().string();
                           for (char& ch : s)
                             ch = std::isalnum(static_cast<unsigned char>(ch)) ? ch : '_';
                           return s;
                         });

// ---------------------------------------------------------------------------
// The error cases, on GLB files edited by tests/glb_edit.h.

class ImportFigureTest : public ::testing::Test {
 protected:
  void SetUp() override {
    figure_ = AvatarDir() / "rigged_figure.glb";
    if (!fs::exists(figure_)) GTEST_SKIP() << figure_ << " is not here";
    dir_ = TempDir();
  }
  void TearDown() override {
    if (!dir_.empty()) fs::remove_all(dir_);
  }
  fs::path figure_, dir_;
};

TEST(ImportErrors, MissingFile) {
  std::string message;
  EXPECT_EQ(ErrorField([] { ImportRiggedAvatar("/nonexistent/irbench/avatar.glb"); }, &message),
            "file");
  EXPECT_NE(message.find("/nonexistent/irbench/avatar.glb"), std::string::npos) << message;
}

// A GLB of a parametric avatar (gltf_export.cc), read back for surgery.
Glb ParametricGlb(const fs::path& dir) {
  AvatarParams params;
  params.name = "surgery";
  WriteAvatarGlb(BuildParametricAvatar(params, BodyShape()), dir / "parametric.glb");
  return ReadGlb(dir / "parametric.glb");
}

// Issue 27.3: a GLB whose accessor claims 10^9 elements made the importer
// allocate ~22 GiB (and spend a minute) before its error. Every accessor's
// and buffer view's size is now checked against the bytes there before
// anything is allocated, and the error names the field.
TEST(ImportErrors, OversizedAccessorsAreRefusedBeforeAllocating) {
  const fs::path dir = TempDir();
  const Glb good = ParametricGlb(dir);
  EXPECT_NO_THROW(ImportRiggedAvatar(dir / "parametric.glb"));
  const int position = good.json["meshes"][0]["primitives"][0]["attributes"]["POSITION"];
  const int view = good.json["accessors"][position]["bufferView"];
  auto field_of = [&](const std::string& name, const std::function<void(nlohmann::json&)>& patch) {
    Glb glb = good;
    patch(glb.json);
    WriteGlb(dir / name, glb);
    std::string message;
    const std::string field = ErrorField([&] { ImportRiggedAvatar(dir / name); }, &message);
    EXPECT_NE(message.find((dir / name).string()), std::string::npos) << message;
    std::printf("%s: %s\n", name.c_str(), message.c_str());
    return field;
  };
  const std::string accessor = "accessors[" + std::to_string(position) + "]";
  EXPECT_EQ(field_of("count.glb",
                     [&](nlohmann::json& j) { j["accessors"][position]["count"] = 1000000000; }),
            accessor + ".count");
  // Without a buffer view the accessor is zeros; it still cannot claim more
  // elements than the input has bytes.
  EXPECT_EQ(field_of("zeros.glb",
                     [&](nlohmann::json& j) {
                       j["accessors"][position]["count"] = 1000000000;
                       j["accessors"][position].erase("bufferView");
                       j["accessors"][position].erase("byteOffset");
                     }),
            accessor + ".count");
  // A buffer view longer than its buffer.
  EXPECT_EQ(field_of("view.glb",
                     [&](nlohmann::json& j) { j["bufferViews"][view]["byteLength"] = 4000000000u; }),
            "bufferViews[" + std::to_string(view) + "].byteLength");
  fs::remove_all(dir);
}

// A chain of 100,000 nodes above the skinned mesh: its world transform is
// composed without recursion (a recursive walk overflowed the stack).
TEST(ImportErrors, DeepNodeChainIsNoStackOverflow) {
  const fs::path dir = TempDir();
  Glb glb = ParametricGlb(dir);
  const int count = 100000;
  const int first = static_cast<int>(glb.json["nodes"].size());
  const int body = first - 1;  // the mesh node comes after the joints
  ASSERT_TRUE(glb.json["nodes"][body].contains("skin"));
  for (int k = 0; k < count; ++k) {
    glb.json["nodes"].push_back({{"children", {k + 1 < count ? first + k + 1 : body}}});
  }
  for (auto& root : glb.json["scenes"][0]["nodes"]) {
    if (root == body) root = first;
  }
  WriteGlb(dir / "chain.glb", glb);
  std::string message;
  EXPECT_EQ(ErrorField([&] { ImportRiggedAvatar(dir / "chain.glb"); }, &message), "(no InputError)")
      << message;
  fs::remove_all(dir);
}

TEST_F(ImportFigureTest, CorruptGlb) {
  std::ifstream in(figure_, std::ios::binary);
  std::string head(200, '\0');
  in.read(head.data(), 200);
  const fs::path truncated = dir_ / "truncated.glb";
  std::ofstream(truncated, std::ios::binary) << head;
  std::string message;
  EXPECT_EQ(ErrorField([&] { ImportRiggedAvatar(truncated); }, &message), "file");
  std::printf("truncated: %s\n", message.c_str());

  std::mt19937 rng(7);
  std::string noise(4096, '\0');
  for (char& ch : noise) ch = static_cast<char>(rng() & 0xff);
  for (const char* name : {"noise.glb", "noise.gltf", "noise.fbx"}) {
    std::ofstream(dir_ / name, std::ios::binary) << noise;
    EXPECT_EQ(ErrorField([&] { ImportRiggedAvatar(dir_ / name); }, &message), "file") << name;
    std::printf("%s: %s\n", name, message.c_str());
  }
  // A GLB header with garbage after it.
  std::string fake = head.substr(0, 20) + noise;
  std::ofstream(dir_ / "garbage.glb", std::ios::binary) << fake;
  EXPECT_EQ(ErrorField([&] { ImportRiggedAvatar(dir_ / "garbage.glb"); }, &message), "file");
}

// Issue 28.5: a rig whose joint names no table knows is mapped by its shape.
// Every skin joint renamed to a meaningless name and an unweighted helper bone
// (an IK target under the pelvis) added to the skin: the hierarchy gives the
// map the name table gives the original, and the same avatar.
class HierarchyMapTest : public ::testing::TestWithParam<const char*> {};

TEST_P(HierarchyMapTest, MeaninglessNamesAndAHelperBoneMapByTheHierarchy) {
  const fs::path original = AvatarDir() / GetParam();
  if (!fs::exists(original)) GTEST_SKIP() << original << " is not here";
  const fs::path dir = TempDir();
  Glb glb = ReadGlb(original);
  const nlohmann::json& first_joint = glb.json["nodes"][glb.json["skins"][0]["joints"][0].get<int>()];
  const std::string root_name = first_joint["name"];
  const std::map<std::string, std::string> renames = RenameJointsMeaninglessly(glb);
  AddHelperJoint(glb, renames.at(root_name), "ik_pole");
  const fs::path file = dir / "renamed.glb";
  WriteGlb(file, glb);

  const Avatar named = ImportRiggedAvatar(original);
  Avatar shaped;
  ASSERT_NO_THROW(shaped = ImportRiggedAvatar(file));
  EXPECT_EQ(shaped.params.source["convention"], "hierarchy");
  const auto& named_map = named.params.source["joint_map"];
  const auto& shaped_map = shaped.params.source["joint_map"];
  for (int j = 0; j < kJointCount; ++j) {
    const std::string canonical = JointName(j);
    if (!named_map.contains(canonical)) continue;
    ASSERT_TRUE(shaped_map.contains(canonical)) << canonical;
    EXPECT_EQ(shaped_map[canonical], renames.at(named_map[canonical].get<std::string>())) << canonical;
  }
  for (int j = 0; j < kJointCount; ++j) {
    EXPECT_LT((shaped.skeleton.bind_position[j] - named.skeleton.bind_position[j]).norm(), 1e-9) << JointName(j);
  }
  EXPECT_NEAR(shaped.params.height_m, named.params.height_m, 1e-9);
  fs::remove_all(dir);
}

INSTANTIATE_TEST_SUITE_P(SharedAvatars, HierarchyMapTest, ::testing::Values("rigged_figure.glb", "CesiumMan.glb"),
                         [](const auto& info) {
                           std::string s = fs::path(info.param).stem().string();
                           for (char& ch : s) ch = std::isalnum(static_cast<unsigned char>(ch)) ? ch : '_';
                           return s;
                         });

TEST_F(ImportFigureTest, ARigWithOneArmIsRefusedNamingTheChain) {
  Glb glb = ReadGlb(figure_);
  MoveWeights(glb, {"arm_joint_R_1", "arm_joint_R_2", "arm_joint_R_3"}, "torso_joint_3");
  RenameJointsMeaninglessly(glb);
  const fs::path file = dir_ / "one_arm.glb";
  WriteGlb(file, glb);
  std::string message;
  EXPECT_EQ(ErrorField([&] { ImportRiggedAvatar(file); }, &message), "skin");
  EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  EXPECT_NE(message.find("no arm chain"), std::string::npos) << message;
  EXPECT_NE(message.find("a neck and two arms need three"), std::string::npos) << message;
  std::printf("%s\n", message.c_str());
}

TEST_F(ImportFigureTest, RenamedArmJointsMapByTheHierarchyOrAJointMap) {
  Glb glb = ReadGlb(figure_);
  RenameNodes(glb, {{"arm_joint_R_1", "bone_a"}, {"arm_joint_R_2", "bone_b"}});
  const fs::path file = dir_ / "renamed_arm.glb";
  WriteGlb(file, glb);
  // No table names the right arm: the hierarchy does.
  const Avatar shaped = ImportRiggedAvatar(file);
  EXPECT_EQ(shaped.params.source["convention"], "hierarchy");
  EXPECT_EQ(shaped.params.source["joint_map"]["right_shoulder"], "bone_a");
  EXPECT_EQ(shaped.params.source["joint_map"]["right_elbow"], "bone_b");
  // A joint map names them too.
  ImportOptions options;
  options.joint_map = {{"right_shoulder", "bone_a"}, {"right_elbow", "bone_b"}};
  EXPECT_NO_THROW(ImportRiggedAvatar(file, options));
  // A joint map that leaves a chain unmapped is still refused, naming it.
  options.joint_map = {{"right_shoulder", "bone_a"}};
  std::string message;
  EXPECT_EQ(ErrorField([&] { ImportRiggedAvatar(file, options); }, &message), "skin");
  EXPECT_NE(message.find("no arm chain"), std::string::npos) << message;
  EXPECT_NE(message.find("right_elbow"), std::string::npos) << message;
}

TEST_F(ImportFigureTest, NoSkinAndNoMesh) {
  Glb glb = ReadGlb(figure_);
  glb.json.erase("skins");
  for (auto& node : glb.json["nodes"]) node.erase("skin");
  glb.json.erase("animations");
  const fs::path file = dir_ / "no_skin.glb";
  WriteGlb(file, glb);
  EXPECT_EQ(ErrorField([&] { ImportRiggedAvatar(file); }), "skin");

  // A skin no mesh uses.
  Glb meshless = ReadGlb(figure_);
  for (auto& node : meshless.json["nodes"]) node.erase("mesh");
  const fs::path no_mesh = dir_ / "no_mesh.glb";
  WriteGlb(no_mesh, meshless);
  EXPECT_EQ(ErrorField([&] { ImportRiggedAvatar(no_mesh); }), "skin");

  const fs::path obj = dir_ / "triangle.obj";
  std::ofstream(obj) << "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
  std::string message;
  EXPECT_EQ(ErrorField([&] { ImportRiggedAvatar(obj); }, &message), "skin");
  std::printf("obj: %s\n", message.c_str());
}

TEST_F(ImportFigureTest, BadOptionsAndHeight) {
  ImportOptions options;
  EXPECT_FALSE(ParseUpAxis("w").has_value());
  EXPECT_EQ(ParseUpAxis("y"), UpAxis::kY);
  options.scale = -1;
  EXPECT_EQ(ErrorField([&] { ImportRiggedAvatar(figure_, options); }), "scale");
  options = {};
  options.joint_map = {{"right_wrist", "no_such_joint"}};
  EXPECT_EQ(ErrorField([&] { ImportRiggedAvatar(figure_, options); }), "joint_map.right_wrist");
  options = {};
  options.scale = 3.0;  // a 4.35 m giant
  EXPECT_EQ(ErrorField([&] { ImportRiggedAvatar(figure_, options); }), "height");
  const fs::path wizard = AvatarDir() / "Wizard.glb";
  if (fs::exists(wizard)) {
    std::string message;
    EXPECT_EQ(ErrorField([&] { ImportRiggedAvatar(wizard); }, &message),
              "height");  // 3 units, glTF metres
    std::printf("%s\n", message.c_str());
  }
}

// The same figure with its left/right joint names swapped: the feet give the
// sides away and the import comes out the same.
TEST_F(ImportFigureTest, SwappedSideNamesAreDetected) {
  Glb glb = ReadGlb(figure_);
  std::map<std::string, std::string> swap;
  for (const char* chain : {"arm_joint_", "leg_joint_"}) {
    for (const char* k : {"1", "2", "3", "5"}) {
      swap[std::string(chain) + "L_" + k] = std::string(chain) + "R_" + k;
      swap[std::string(chain) + "R_" + k] = std::string(chain) + "L_" + k;
    }
  }
  RenameNodes(glb, swap);
  const fs::path file = dir_ / "swapped.glb";
  WriteGlb(file, glb);
  const Avatar reference = ImportRiggedAvatar(figure_);
  const Avatar swapped = ImportRiggedAvatar(file);
  for (int j = 0; j < kJointCount; ++j) {
    EXPECT_LT((swapped.skeleton.bind_position[j] - reference.skeleton.bind_position[j]).norm(),
              1e-6)
        << JointName(j);
  }
  ASSERT_EQ(swapped.bind_vertices.size(), reference.bind_vertices.size());
  for (size_t i = 0; i < swapped.bind_vertices.size(); ++i) {
    ASSERT_LT((swapped.bind_vertices[i].position - reference.bind_vertices[i].position).norm(),
              1e-5f)
        << i;
  }
}

// Up axis given or found, same result; Collada through assimp, same body.
TEST_F(ImportFigureTest, UpAxisOptionAndAssimpPath) {
  const Avatar reference = ImportRiggedAvatar(figure_);
  ImportOptions options;
  options.up_axis = UpAxis::kY;  // the figure's node tree turns its z-up mesh y-up
  const Avatar y_up = ImportRiggedAvatar(figure_, options);
  for (int j = 0; j < kJointCount; ++j) {
    EXPECT_LT((y_up.skeleton.bind_position[j] - reference.skeleton.bind_position[j]).norm(), 1e-6)
        << JointName(j);
  }

  // glTF -> Collada with assimp's own exporter, then imported through assimp.
  Assimp::Importer importer;
  const aiScene* scene = importer.ReadFile(figure_.string(), 0);
  ASSERT_NE(scene, nullptr) << importer.GetErrorString();
  const fs::path dae = dir_ / "figure.dae";
  Assimp::Exporter exporter;
  ASSERT_EQ(exporter.Export(scene, "collada", dae.string()), AI_SUCCESS)
      << exporter.GetErrorString();
  Avatar from_dae;
  ASSERT_NO_THROW(from_dae = ImportRiggedAvatar(dae));
  EXPECT_NEAR(from_dae.params.height_m, 1.450, 0.03);
  for (int j = 0; j < kJointCount; ++j) {
    EXPECT_LT((from_dae.skeleton.bind_position[j] - reference.skeleton.bind_position[j]).norm(),
              0.01)
        << JointName(j);
  }
  for (const auto& w : from_dae.bone_weight) EXPECT_NEAR(w[0] + w[1] + w[2] + w[3], 1.0f, 1e-5f);
  std::vector<MeshVertex> skinned;
  SkinVertices(from_dae, ForwardKinematics(from_dae.skeleton, Pose()), skinned);
  for (size_t i = 0; i < skinned.size(); ++i) {
    ASSERT_LT((skinned[i].position - from_dae.bind_vertices[i].position).norm(), 1e-5f);
  }
}

// A file in centimetres with no unit (assimp's own binary format, the figure
// scaled by 100 at its root): read as centimetres; the scale option wins.
TEST_F(ImportFigureTest, CentimetresWithoutUnitMetadata) {
  Assimp::Importer importer;
  ASSERT_NE(importer.ReadFile(figure_.string(), 0), nullptr) << importer.GetErrorString();
  aiScene* scene = importer.GetOrphanedScene();
  scene->mRootNode->mTransformation =
      aiMatrix4x4(aiVector3D(100, 100, 100), aiQuaternion(), aiVector3D(0, 0, 0)) *
      scene->mRootNode->mTransformation;
  const fs::path file = dir_ / "figure_cm.assbin";
  Assimp::Exporter exporter;
  const aiReturn exported = exporter.Export(scene, "assbin", file.string());
  delete scene;
  ASSERT_EQ(exported, AI_SUCCESS) << exporter.GetErrorString();
  const Avatar reference = ImportRiggedAvatar(figure_);
  const Avatar cm = ImportRiggedAvatar(file);
  EXPECT_NEAR(cm.params.height_m, reference.params.height_m, 0.005);
  for (int j = 0; j < kJointCount; ++j) {
    EXPECT_LT((cm.skeleton.bind_position[j] - reference.skeleton.bind_position[j]).norm(), 0.005)
        << JointName(j);
  }
  ImportOptions options;
  options.scale = 0.012;  // the caller's scale is taken as given
  EXPECT_NEAR(ImportRiggedAvatar(file, options).params.height_m, 1.2 * reference.params.height_m,
              0.01);
}

// Our own export (canonical joint names) imports without ../shared: the same
// joints, the same height, the same truth markers; independent of the test
// avatars beside the checkout.
class OwnExportTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = TempDir() / "own";
    fs::create_directories(dir_);
    person_ = LoadAvatar(fs::path(IRBENCH_SOURCE_DIR) / "avatars" / "p3.json");
    glb_ = dir_ / "p3.glb";
    WriteAvatarGlb(person_, glb_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_, glb_;
  Avatar person_;
};

TEST_F(OwnExportTest, ImportsOntoTheSameSkeleton) {
  Glb glb = ReadGlb(glb_);
  std::vector<std::string> names;
  for (const auto& node : glb.json["nodes"]) names.push_back(node.value("name", ""));
  EXPECT_EQ(MapRigJoints(names, {}).convention, "irbench");

  const Avatar imported = LoadAvatar(glb_);  // a mesh file is an avatar too
  EXPECT_EQ(imported.params.kind, "mesh");
  EXPECT_EQ(imported.params.name, "p3");
  EXPECT_NEAR(imported.params.height_m, person_.params.height_m, 0.002);
  // Above the hips the generator's T-pose is the canonical one: re-posing
  // changes nothing beyond float rounding (the import puts the pelvis over the
  // origin). The generator's legs converge slightly towards the ankles; the
  // import straightens them to vertical, keeping the bone lengths.
  const auto& ours = imported.skeleton.bind_position;
  const auto& theirs = person_.skeleton.bind_position;
  const Eigen::Vector3d shift(theirs[kPelvis].x(), theirs[kPelvis].y(), 0);
  for (int j = 0; j < kJointCount; ++j) {
    if (j == kRightKnee || j == kRightAnkle || j == kLeftKnee || j == kLeftAnkle) continue;
    EXPECT_LT((ours[j] + shift - theirs[j]).norm(), 1e-4) << JointName(j);
  }
  for (int hip : {kRightHip, kLeftHip}) {
    for (int j = hip; j < hip + 2; ++j) {
      const Eigen::Vector3d bone = ours[j + 1] - ours[j];
      EXPECT_NEAR(bone.norm(), (theirs[j + 1] - theirs[j]).norm(), 1e-4) << JointName(j);
      EXPECT_LT(std::hypot(bone.x(), bone.y()), 1e-6) << JointName(j) << " not vertical";
    }
  }
  EXPECT_EQ(imported.bind_vertices.size(), person_.bind_vertices.size());
  EXPECT_EQ(imported.indices, person_.indices);
  // Markers: head centre and hand tips within a few cm of the generator's.
  for (const BoneMarker& m : person_.markers) {
    bool found = false;
    for (const BoneMarker& i : imported.markers) {
      if (i.name != m.name) continue;
      found = true;
      EXPECT_EQ(i.joint, m.joint) << m.name;
      EXPECT_LT((i.offset_in_joint - m.offset_in_joint).norm(), 0.04) << m.name;
    }
    EXPECT_TRUE(found) << m.name;
  }
}

TEST_F(OwnExportTest, MeshAvatarFileCarriesTheImportOptions) {
  const fs::path json = dir_ / "tall.json";
  std::ofstream(json) << R"({"format": "irbench.avatar/1", "kind": "mesh", "name": "tall",
    "file": "p3.glb", "scale": 1.1, "up_axis": "y", "style": {"handedness": "left"}})";
  const Avatar tall = LoadAvatar(json);
  EXPECT_EQ(tall.params.kind, "mesh");
  EXPECT_EQ(tall.params.name, "tall");
  EXPECT_NEAR(tall.params.height_m, 1.1 * person_.params.height_m, 0.003);
  EXPECT_EQ(tall.params.style["handedness"], "left");

  // Each bad field named in the avatar file (or, for the mesh, in the mesh).
  struct Bad {
    const char* json;
    const char* file;  // "json" or "glb"
    const char* field;
  };
  const Bad cases[] = {
      {R"("file": "missing.glb")", "json", "file"},
      {R"("file": "p3.glb", "scale": -1)", "json", "scale"},
      {R"("file": "p3.glb", "up_axis": "x")", "json", "up_axis"},
      {R"("file": "p3.glb", "height_m": 1.8)", "json", "height_m"},
      {R"("file": "p3.glb", "joint_map": {"right_elbow": "nope"})", "json", "joint_map.right_elbow"},
      {R"("file": "p3.glb", "joint_map": {"elbow": "right_elbow"})", "json", "joint_map.elbow"},
      {R"("file": "p3.glb", "scale": 2)", "glb", "height"},
  };
  for (const Bad& b : cases) {
    const fs::path bad = dir_ / "bad.json";
    std::ofstream(bad) << R"({"format": "irbench.avatar/1", "kind": "mesh", )" << b.json << "}";
    try {
      LoadAvatar(bad);
      ADD_FAILURE() << b.json << ": no error";
    } catch (const InputError& e) {
      EXPECT_EQ(e.field(), b.field) << e.what();
      EXPECT_EQ(fs::path(e.file()).filename(), std::string(b.file) == "json" ? "bad.json" : "p3.glb")
          << e.what();
    }
  }
  // A tube avatar does not take import options.
  const fs::path tube = dir_ / "tube.json";
  std::ofstream(tube) << R"({"format": "irbench.avatar/1", "kind": "tube", "height_m": 1.7, "scale": 2})";
  try {
    LoadAvatar(tube);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "scale") << e.what();
  }
}

}  // namespace
}  // namespace irbench
