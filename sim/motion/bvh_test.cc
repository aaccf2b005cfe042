#include "sim/motion/bvh.h"

#include <assimp/Importer.hpp>
#include <assimp/scene.h>
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <optional>
#include <random>
#include <utility>

#include "common/error.h"
#include "sim/body/avatar.h"
#include "sim/motion/library.h"
#include "sim/motion/motion_test_util.h"
#include "sim/motion/retarget.h"
#include "tests/test_util.h"

namespace irbench {
namespace {
using irbench::testing::Person;
using irbench::testing::Replace;
namespace fs = std::filesystem;

const char* kSmallBvh =
    "HIERARCHY\n"
    "ROOT Hips\n"
    "{\n"
    "\tOFFSET 0 0 0\n"
    "\tCHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n"
    "\tJOINT Arm\n"
    "\t{\n"
    "\t\tOFFSET 10 0 0\n"
    "\t\tCHANNELS 3 Zrotation Yrotation Xrotation\n"
    "\t\tEnd Site\n"
    "\t\t{\n"
    "\t\t\tOFFSET 0 -5 0\n"
    "\t\t}\n"
    "\t}\n"
    "}\n"
    "MOTION\n"
    "Frames:\t2\n"
    "Frame Time:\t0.0083333\n"
    "1 2 3 0 0 0 90 0 0\n"
    "1 2 3 90 0 0 0 0 0\n";

// Line of an InputError's field "line N".
int LineOf(const std::string& text) {
  try {
    ParseBvh(text, "bad.bvh");
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), "bad.bvh");
    EXPECT_EQ(e.field().rfind("line ", 0), 0u) << e.what();
    return std::stoi(e.field().substr(5));
  }
  ADD_FAILURE() << "no error";
  return -1;
}

TEST(BvhTest, ForwardKinematicsMatchesHandComputation) {
  const MocapClip clip = BvhToClip(ParseBvh(kSmallBvh, "small.bvh"));
  ASSERT_EQ(clip.joint_names.size(), 3u);
  EXPECT_EQ(clip.joint_names[2], "Arm_end");
  EXPECT_NEAR(clip.frame_time, 0.0083333, 1e-12);
  // Frame 0: the Arm joint turns 90° about z; its end (0, -5, 0) goes to (5, 0, 0).
  const Eigen::Vector3d end0 = clip.frames[0].position[2];
  EXPECT_NEAR((end0 - Eigen::Vector3d(1 + 10 + 5, 2, 3)).norm(), 0, 1e-12);
  // Frame 1: the root turns 90° about z: the arm offset (10, 0, 0) -> (0, 10, 0).
  EXPECT_NEAR((clip.frames[1].position[1] - Eigen::Vector3d(1, 12, 3)).norm(), 0, 1e-12);
  EXPECT_NEAR((clip.frames[1].position[2] - Eigen::Vector3d(1 + 5, 12, 3)).norm(), 0, 1e-12);
}

TEST(BvhTest, CrlfAndTabsParseLikeLf) {
  std::string crlf;
  for (char c : std::string(kSmallBvh)) {
    if (c == '\n') crlf += "\r\n"; else crlf += (c == ' ' ? '\t' : c);
  }
  const BvhFile a = ParseBvh(kSmallBvh, "a.bvh"), b = ParseBvh(crlf, "b.bvh");
  ASSERT_EQ(a.frames.size(), b.frames.size());
  EXPECT_EQ(a.frames, b.frames);
  EXPECT_EQ(a.joints.size(), b.joints.size());
}

TEST(BvhTest, EulerDecompositionInvertsEveryOrder) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> angle(-170, 170), mid(-85, 85);
  using C = BvhChannel;
  const std::vector<std::vector<C>> orders = {
      {C::kXrotation, C::kYrotation, C::kZrotation}, {C::kXrotation, C::kZrotation, C::kYrotation},
      {C::kYrotation, C::kXrotation, C::kZrotation}, {C::kYrotation, C::kZrotation, C::kXrotation},
      {C::kZrotation, C::kXrotation, C::kYrotation}, {C::kZrotation, C::kYrotation, C::kXrotation}};
  for (const auto& order : orders) {
    for (int i = 0; i < 50; ++i) {
      const Eigen::Vector3d e(angle(rng), mid(rng), angle(rng));
      Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
      for (int k = 0; k < 3; ++k) {
        const int axis = static_cast<int>(order[k]) - 3;
        q = q * Eigen::AngleAxisd(e[k] * M_PI / 180, Eigen::Vector3d::Unit(axis));
      }
      const Eigen::Vector3d back = EulerDegrees(q, order);
      EXPECT_NEAR((back - e).norm(), 0, 1e-8);
    }
  }
}

TEST(BvhTest, BadInputNamesTheLine) {
  const std::string good = kSmallBvh;
  // A joint without a CHANNELS line (line 9 holds it).
  EXPECT_EQ(LineOf(Replace(good, "\t\tCHANNELS 3 Zrotation Yrotation Xrotation\n", "")), 9);
  // A frame with too few values (line 20 is the first frame).
  EXPECT_EQ(LineOf(Replace(good, "1 2 3 0 0 0 90 0 0\n", "1 2 3 0 0 0 90 0\n")), 19);
  EXPECT_EQ(LineOf(Replace(good, "1 2 3 90 0 0 0 0 0\n", "1 2 3 90 nan 0 0 0 0\n")), 20);
  // An unknown rotation order: a repeated axis, or a channel that does not exist.
  EXPECT_EQ(LineOf(Replace(good, "Zrotation Yrotation Xrotation", "Zrotation Zrotation Xrotation")), 9);
  EXPECT_EQ(LineOf(Replace(good, "Zrotation Yrotation Xrotation", "Zrotation Wrotation Xrotation")), 9);
  EXPECT_EQ(LineOf(Replace(good, "Frames:\t2", "Frames:\t3")), 20);
}

// The InputError of parsing `text`; fails the test when there is none.
InputError ErrorOf(const std::string& text) {
  try {
    ParseBvh(text, "bad.bvh");
  } catch (const InputError& e) {
    return e;
  }
  ADD_FAILURE() << "no error";
  return InputError("", "", "");
}

// Issue 27.3: a chain of 15,000 nested joints overflowed the recursive
// parser's stack (SIGSEGV); nesting is capped at kMaxBvhDepth levels.
TEST(BvhTest, DeepNestingIsAnErrorNotACrash) {
  const int depth = 15000;
  std::string text = "HIERARCHY\nROOT j0\n{\nOFFSET 0 0 0\nCHANNELS 3 Zrotation Xrotation Yrotation\n";
  for (int j = 1; j < depth; ++j) {
    text += "JOINT j" + std::to_string(j) + "\n{\nOFFSET 0 1 0\nCHANNELS 3 Zrotation Xrotation Yrotation\n";
  }
  for (int j = 0; j < depth; ++j) text += "}\n";
  text += "MOTION\nFrames: 0\nFrame Time: 0.01\n";
  const InputError e = ErrorOf(text);
  // Joint j256 (level 257) is named on line 2 + 4 * 256.
  EXPECT_EQ(e.field(), "line " + std::to_string(2 + 4 * kMaxBvhDepth)) << e.what();
  EXPECT_NE(e.message().find("deeper than 256"), std::string::npos) << e.what();
  // At the cap itself the file is fine.
  std::string ok = "HIERARCHY\nROOT j0\n{\nOFFSET 0 0 0\nCHANNELS 0\n";
  for (int j = 1; j < kMaxBvhDepth; ++j) ok += "JOINT j" + std::to_string(j) + "\n{\nOFFSET 0 1 0\nCHANNELS 0\n";
  for (int j = 0; j < kMaxBvhDepth; ++j) ok += "}\n";
  ok += "MOTION\nFrames: 0\nFrame Time: 0.01\n";
  EXPECT_EQ(ParseBvh(ok, "ok.bvh").joints.size(), static_cast<size_t>(kMaxBvhDepth));
}

// Issue 27.3: two joints with one name were accepted (a knee could end up
// above the hip in the truth); refused naming the line and the name.
TEST(BvhTest, DuplicateJointNamesAreRefused) {
  const std::string good = kSmallBvh;
  InputError e = ErrorOf(Replace(good, "JOINT Arm", "JOINT Hips"));
  EXPECT_EQ(e.file(), "bad.bvh");
  EXPECT_EQ(e.field(), "line 6") << e.what();
  EXPECT_NE(e.message().find("'Hips'"), std::string::npos) << e.what();
  EXPECT_NE(e.message().find("line 2"), std::string::npos) << e.what();
  // A joint named like another joint's End Site ("Hips_end", line 6).
  e = ErrorOf(Replace(good, "\tJOINT Arm", "\tEnd Site\n\t{\n\t\tOFFSET 0 1 0\n\t}\n\tJOINT Hips_end"));
  EXPECT_EQ(e.field(), "line 10") << e.what();
  EXPECT_NE(e.message().find("'Hips_end'"), std::string::npos) << e.what();
}

// Issue 27.3: -1e308 in a rotation channel was accepted and wrote 'nan' into
// the truth; non-finite and absurd values are refused naming the line.
TEST(BvhTest, AbsurdValuesAreRefused) {
  const std::string good = kSmallBvh;
  const std::string frame0 = "1 2 3 0 0 0 90 0 0\n";
  auto message_at = [&](const std::string& text, int line) {
    const InputError e = ErrorOf(text);
    EXPECT_EQ(e.field(), "line " + std::to_string(line)) << e.what();
    return e.message();
  };
  EXPECT_NE(message_at(Replace(good, frame0, "1 2 3 -1e308 0 0 90 0 0\n"), 19).find("rotation"),
            std::string::npos);
  EXPECT_NE(message_at(Replace(good, frame0, "1 2 3 0 0 0 90 0 1e7\n"), 19).find("degrees"),
            std::string::npos);
  message_at(Replace(good, frame0, "1 2 3 0 inf 0 90 0 0\n"), 19);
  message_at(Replace(good, frame0, "1 2 3 0 0 0 90 -nan 0\n"), 19);
  message_at(Replace(good, frame0, "1 2 3 0 0 0 90 0 1e400\n"), 19);
  EXPECT_NE(message_at(Replace(good, frame0, "1 -2e5 3 0 0 0 90 0 0\n"), 19).find("position"),
            std::string::npos);
  EXPECT_NE(message_at(Replace(good, "OFFSET 10 0 0", "OFFSET 10 0 1e300"), 8).find("OFFSET"),
            std::string::npos);
  message_at(Replace(good, "Frame Time:\t0.0083333", "Frame Time:\t1e9"), 18);
  message_at(Replace(good, "Frame Time:\t0.0083333", "Frame Time:\t1e-300"), 18);
  // Within the limits: a large but real rotation and position.
  EXPECT_NO_THROW(ParseBvh(Replace(good, frame0, "1e4 2 3 7200 0 0 90 0 -999999\n"), "ok.bvh"));
}

// A 'Frames:' count far beyond the file's lines is an error without first
// reserving room for that many frames.
TEST(BvhTest, HugeFrameCountIsAnErrorWithoutAllocating) {
  const InputError e = ErrorOf(Replace(kSmallBvh, "Frames:\t2", "Frames:\t99999999"));
  EXPECT_EQ(e.field(), "line 20") << e.what();
}

TEST(BvhTest, ExportReimportRoundTrip) {
  const Avatar avatar = Person("p2");
  MotionContext ctx;
  ctx.avatar = &avatar;
  ctx.style = StyleFor("p2", 3);
  const MotionPtr motion = BuildLibraryMotion("flap_both", nullptr, ctx);
  const BvhFile out = MotionToBvh(*motion, avatar.skeleton, 30);
  const std::string text = WriteBvh(out);
  const BvhFile in = ParseBvh(text, "roundtrip.bvh");
  ASSERT_EQ(in.frames.size(), out.frames.size());
  ASSERT_EQ(in.channel_count, out.channel_count);
  double worst_rad = 0, worst_m = 0;
  for (size_t f = 0; f < in.frames.size(); ++f) {
    for (const BvhJoint& j : in.joints) {
      for (size_t k = 0; k < j.channels.size(); ++k) {
        const double a = in.frames[f][j.first_channel + k], b = out.frames[f][j.first_channel + k];
        if (j.channels[k] >= BvhChannel::kXrotation) {
          worst_rad = std::max(worst_rad, std::abs(a - b) * M_PI / 180);
        } else {
          worst_m = std::max(worst_m, std::abs(a - b));
        }
      }
    }
  }
  EXPECT_LT(worst_rad, 1e-4);
  EXPECT_LT(worst_m, 1e-4);
  // Re-imported and retargeted onto the same body, the joints come back.
  MocapClip clip = BvhToClip(in);
  clip.convention = DetectConvention(clip);
  EXPECT_EQ(clip.convention, "irbench");
  const auto back = Retarget(clip, avatar.skeleton);
  double worst_joint = 0;
  for (double t = 0; t < motion->Duration(); t += 0.2) {
    const JointTransforms a = ForwardKinematics(avatar.skeleton, motion->At(t));
    const JointTransforms b = ForwardKinematics(avatar.skeleton, back->At(t));
    const auto ta = TruthJoints(avatar, a), tb = TruthJoints(avatar, b);
    for (size_t j = 0; j < ta.size(); ++j) worst_joint = std::max(worst_joint, (ta[j] - tb[j]).norm());
  }
  EXPECT_LT(worst_joint, 0.002);

  // assimp reads the exported file with every joint.
  const fs::path file = fs::temp_directory_path() / "irbench_roundtrip_test.bvh";
  std::ofstream(file) << text;
  Assimp::Importer importer;
  const aiScene* scene = importer.ReadFile(file.string(), 0);
  ASSERT_NE(scene, nullptr) << importer.GetErrorString();
  for (int j = 0; j < kJointCount; ++j) {
    EXPECT_NE(scene->mRootNode->FindNode(JointName(j)), nullptr) << JointName(j);
  }
  ASSERT_EQ(scene->mNumAnimations, 1u);
  EXPECT_EQ(scene->mAnimations[0]->mNumChannels, static_cast<unsigned>(kJointCount));
  fs::remove(file);
}

// The floor contacts of `motion` (in each half second, the lower ankle's
// lowest point), split at the middle of the path they cover along its longest
// direction: the lowest contact of each half, or nothing when the contacts
// span less than `min_span` metres.
std::optional<std::pair<double, double>> FloorAtPathEnds(const RetargetedMotion& motion, const Skeleton& skeleton,
                                                         double min_span) {
  std::vector<Eigen::Vector3d> contacts;
  for (double t0 = 0; t0 + 0.5 <= motion.Duration(); t0 += 0.5) {
    Eigen::Vector3d low(0, 0, std::numeric_limits<double>::infinity());
    for (double t = t0; t < t0 + 0.5; t += motion.frame_time()) {
      const JointTransforms fk = ForwardKinematics(skeleton, motion.At(t));
      for (int ankle : {kRightAnkle, kLeftAnkle}) {
        if (fk[ankle].translation().z() < low.z()) low = fk[ankle].translation();
      }
    }
    contacts.push_back(low);
  }
  if (contacts.size() < 2) return std::nullopt;
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (const auto& c : contacts) mean += c.head<2>() / contacts.size();
  Eigen::Matrix2d cov = Eigen::Matrix2d::Zero();
  for (const auto& c : contacts) cov += (c.head<2>() - mean) * (c.head<2>() - mean).transpose();
  const Eigen::Vector2d axis = Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(cov).eigenvectors().col(1);
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (const auto& c : contacts) {
    lo = std::min(lo, axis.dot(c.head<2>() - mean));
    hi = std::max(hi, axis.dot(c.head<2>() - mean));
  }
  if (hi - lo < min_span) return std::nullopt;
  std::pair<double, double> floor(std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity());
  for (const auto& c : contacts) {
    double& half = axis.dot(c.head<2>() - mean) < (lo + hi) / 2 ? floor.first : floor.second;
    half = std::min(half, c.z());
  }
  return floor;
}

// A capture whose floor leans (the whole clip turned 2.5 degrees about a
// horizontal axis across the walk, its rest skeleton upright): retargeted, the
// person walks on a level floor and moves as in the level capture. (A lean
// about the walk's own line is barely seen by the feet of a straight walk, and
// the levelling leaves most of it.)
TEST(RetargetTest, LevelsACaptureWhoseFloorLeans) {
  const Avatar avatar = Person("p2");
  MotionContext ctx;
  ctx.avatar = &avatar;
  ctx.style = StyleFor("p2", 5);
  const MotionPtr walk = BuildLibraryMotion("walk", {{"to", {0.0, 3.0}}}, ctx);
  MocapClip level = BvhToClip(MotionToBvh(*walk, avatar.skeleton, 60));
  level.convention = DetectConvention(level);
  MocapClip leaning = level;
  const Eigen::Quaterniond lean(Eigen::AngleAxisd(2.5 * M_PI / 180, Eigen::Vector3d::UnitX()));
  for (MocapClip::Frame& frame : leaning.frames) {
    for (Eigen::Vector3d& p : frame.position) p = lean * p;
    for (Eigen::Quaterniond& q : frame.rotation) q = lean * q;
  }
  const auto a = Retarget(level, avatar.skeleton), b = Retarget(leaning, avatar.skeleton);
  const auto ends_a = FloorAtPathEnds(*a, avatar.skeleton, 2.0), ends_b = FloorAtPathEnds(*b, avatar.skeleton, 2.0);
  ASSERT_TRUE(ends_a && ends_b);
  EXPECT_NEAR(ends_a->first, ends_a->second, 0.005);
  EXPECT_NEAR(ends_b->first, ends_b->second, 0.005);  // 13 cm apart without the levelling
  double worst = 0;
  for (double t = 0; t <= a->Duration(); t += 0.1) {
    const JointTransforms fa = ForwardKinematics(avatar.skeleton, a->At(t));
    const JointTransforms fb = ForwardKinematics(avatar.skeleton, b->At(t));
    for (int j = 0; j < kJointCount; ++j) worst = std::max(worst, (fa[j].translation() - fb[j].translation()).norm());
  }
  EXPECT_LT(worst, 0.01);
}

// Every CMU clip beside the checkout: loads, retargets onto three persons, and
// keeps the source's upper-arm and forearm directions.
TEST(CmuClipsTest, RetargetKeepsArmDirections) {
  const std::vector<fs::path> files = irbench::testing::CmuClips();
  if (files.empty()) GTEST_SKIP() << "no CMU clips in ../shared/data/mocap/cmu";
  ASSERT_GE(files.size(), 1u);
  const Avatar persons[3] = {Person("p1"), Person("p2"), Person("p3")};
  double worst_all = 0;
  for (const fs::path& file : files) {
    const MocapClip clip = LoadMocap(file);
    EXPECT_FALSE(clip.convention.empty()) << file;
    if (file.stem() == "16_01") {
      EXPECT_NEAR(clip.frame_time, 1.0 / 120, 1e-9);
    }
    for (const Avatar& avatar : persons) {
      const auto motion = Retarget(clip, avatar.skeleton);
      double worst = 0;
      const size_t step = std::max<size_t>(1, clip.frames.size() / 25);
      for (size_t f = 0; f < clip.frames.size(); f += step) {
        const JointTransforms fk = ForwardKinematics(avatar.skeleton, motion->At(f * clip.frame_time));
        for (const char* side : {"right", "left"}) {
          const std::string s = side;
          const int sh = *JointFromName(s + "_shoulder");
          for (int seg = 0; seg < 2; ++seg) {
            const int a = motion->source_joint[sh + seg];
            const int b = motion->source_joint[sh + seg + 1];
            const Eigen::Vector3d src =
                motion->world_from_source * (clip.frames[f].position[b] - clip.frames[f].position[a]);
            const Eigen::Vector3d ours = fk[sh + seg + 1].translation() - fk[sh + seg].translation();
            const double deg = std::acos(std::clamp(src.normalized().dot(ours.normalized()), -1.0, 1.0)) * 180 / M_PI;
            worst = std::max(worst, deg);
          }
        }
      }
      EXPECT_LT(worst, 2.0) << file.filename() << " on " << avatar.params.name;
      worst_all = std::max(worst_all, worst);
      // Up is the file's +y (BVH's up) within the floor's lean (under 3 degrees).
      EXPECT_GT((motion->world_from_source * Eigen::Vector3d::UnitY()).z(), std::cos(3 * M_PI / 180))
          << file.filename();
      // The floor is level: over a path of 2 m or more, the feet touch it as
      // low in its first half as in its second.
      if (const auto ends = FloorAtPathEnds(*motion, avatar.skeleton, 2.0)) {
        std::printf("  %s on %s: floor at the path's ends %.3f %.3f m\n", file.stem().c_str(),
                    avatar.params.name.c_str(), ends->first, ends->second);
        EXPECT_NEAR(ends->first, ends->second, 0.015) << file.filename() << " on " << avatar.params.name;
      }
      const JointTransforms fk0 = ForwardKinematics(avatar.skeleton, motion->At(0));
      EXPECT_GT(fk0[kHead].translation().z(), 0.6 * avatar.params.height_m) << file.filename();
    }
  }
  std::printf("%zu CMU clips x 3 persons: worst upper-arm/forearm direction difference %.2e deg\n",
              files.size(), worst_all);
}

}  // namespace
}  // namespace irbench
