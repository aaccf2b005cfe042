#include "sim/motion/asf_amc.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>
#include <string>

#include "common/error.h"
#include "sim/motion/motion_test_util.h"

namespace irbench {
namespace {
using irbench::testing::Replace;

using Eigen::AngleAxisd;
using Eigen::Matrix3d;
using Eigen::Vector3d;

constexpr double kDeg = std::numbers::pi / 180.0;

// root -> lhumerus -> lradius, root -> lowerback. lhumerus points along +x
// with its local axes turned 90 degrees about z (local x = world y);
// lradius points along -y with its local axes turned 45 degrees about y.
const char kAsf[] = R"(# A small CMU-style skeleton.
:version 1.10
:name VICON
:units
  mass 1.0
  length 0.45
  angle deg
:documentation
   Free text: not a section.
:root
   order TX TY TZ RX RY RZ
   axis XYZ
   position 1 2 3
   orientation 0 0 0
:bonedata
  begin
     id 1
     name lhumerus
     direction 1 0 0
     length 10
     axis 0 0 90  XYZ
     dof rx ry rz
     limits (-90.0 90.0)
            (-90.0 90.0)
            (-inf inf)
  end
  begin
     id 2
     name lradius
     direction 0 -1 0
     length 8
     axis 0 45 0 XYZ
     dof rx
     limits (-10.0 170.0)
  end
  begin
     id 3
     name lowerback
     direction 0 0 1
     length 5
     axis 0 0 0 XYZ
  end
:hierarchy
  begin
    root lhumerus lowerback
    lhumerus lradius
  end
)";

const char kAmc[] = R"(# comment
:FULLY-SPECIFIED
:DEGREES
1
root 0 0 0 0 0 0
lhumerus 0 0 0
lradius 0
2
root 0 0 0 0 0 0
lhumerus 30 0 0
3
root 0 0 0 0 0 0
lradius 60
4
root 0.5 -1 2 0 0 90
)";

// 1-based number of the first line of `text` containing `needle`.
int LineOf(const std::string& text, const std::string& needle) {
  const size_t at = text.find(needle);
  EXPECT_NE(at, std::string::npos) << needle;
  return 1 + static_cast<int>(std::count(text.begin(), text.begin() + at, '\n'));
}

std::string ReplaceAll(std::string text, const std::string& from, const std::string& to) {
  for (size_t at = text.find(from); at != std::string::npos; at = text.find(from, at + to.size())) {
    text.replace(at, from.size(), to);
  }
  return text;
}

// Full double precision, unlike std::to_string.
std::string Fmt(double v) {
  std::ostringstream out;
  out.precision(17);
  out << v;
  return out.str();
}

// CRLF line ends, and tabs among the spaces.
std::string Crlf(const std::string& text) {
  return ReplaceAll(ReplaceAll(text, "\n", "\r\n"), " ", " \t");
}

MocapClip Parse(const std::string& asf = kAsf, const std::string& amc = kAmc) {
  return ParseAsfAmc(asf, "test.asf", amc, "dir/test_01.amc");
}

Vector3d Position(const MocapClip& clip, int frame, const std::string& joint) {
  const int j = clip.FindJoint(joint);
  EXPECT_GE(j, 0) << joint;
  return clip.frames[frame].position[j];
}

// Runs the parse expecting an InputError naming `file` and `field` whose
// message contains `fragment`.
void ExpectError(const std::string& asf,
                 const std::string& amc,
                 const std::string& file,
                 int line,
                 const std::string& fragment) {
  try {
    Parse(asf, amc);
    ADD_FAILURE() << "no error; expected " << fragment;
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), file) << e.what();
    EXPECT_EQ(e.field(), "line " + std::to_string(line)) << e.what();
    EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
  }
}

TEST(AsfAmcTest, JointsNamesParentsAndMetadata) {
  const MocapClip clip = Parse();
  const std::vector<std::string> names = {"root",        "lhumerus",  "lradius",
                                          "lradius_end", "lowerback", "lowerback_end"};
  EXPECT_EQ(clip.joint_names, names);
  EXPECT_EQ(clip.parent, (std::vector<int>{-1, 0, 1, 2, 0, 4}));
  EXPECT_EQ(clip.name, "test_01");
  EXPECT_EQ(clip.convention, "cmu");
  EXPECT_DOUBLE_EQ(clip.frame_time, 1.0 / 120.0);
  ASSERT_EQ(clip.frames.size(), 4u);
  EXPECT_NEAR(clip.Duration(), 3.0 / 120.0, 1e-15);
}

TEST(AsfAmcTest, UnitsLengthIsInchesOverLength) {
  // CMU FAQ: metres = units * (1 / 0.45) * 2.54 / 100.
  EXPECT_NEAR(Parse().metres_per_unit, 0.056444, 1e-6);
}

TEST(AsfAmcTest, RestPositionsAreSumsOfDirectionTimesLength) {
  const MocapClip clip = Parse();
  const Vector3d root(1, 2, 3);
  const Vector3d elbow = root + 10 * Vector3d(1, 0, 0);
  const Vector3d wrist = elbow + 8 * Vector3d(0, -1, 0);
  const Vector3d back_tip = root + 5 * Vector3d(0, 0, 1);
  const std::vector<Vector3d> expected = {root, root, elbow, wrist, root, back_tip};
  ASSERT_EQ(clip.rest_position.size(), expected.size());
  for (size_t j = 0; j < expected.size(); ++j) {
    EXPECT_LT((clip.rest_position[j] - expected[j]).norm(), 1e-12) << clip.joint_names[j];
    // Frame 1 has every value zero: the rest pose, identity rotations.
    EXPECT_LT((clip.frames[0].position[j] - expected[j]).norm(), 1e-12) << clip.joint_names[j];
    EXPECT_LT(clip.frames[0].rotation[j].angularDistance(Eigen::Quaterniond::Identity()), 1e-12);
  }
}

TEST(AsfAmcTest, AxisConjugatesTheDofRotation) {
  // lhumerus axis (0 0 90 XYZ) maps local x to world y, so `rx 30` turns the
  // arm 30 degrees about world y: +x tips toward -z.
  const MocapClip clip = Parse();
  const Vector3d root(1, 2, 3);
  const Matrix3d about_y = AngleAxisd(30 * kDeg, Vector3d::UnitY()).toRotationMatrix();
  const Vector3d elbow = root + 10 * Vector3d(std::cos(30 * kDeg), 0, -std::sin(30 * kDeg));
  EXPECT_LT((Position(clip, 1, "lradius") - elbow).norm(), 1e-9);
  EXPECT_LT((about_y * Vector3d(10, 0, 0) - (elbow - root)).norm(), 1e-12);
  // The forearm rides along, rotated by the same world rotation.
  EXPECT_LT((Position(clip, 1, "lradius_end") - (elbow + about_y * Vector3d(0, -8, 0))).norm(),
            1e-9);
  const int humerus = clip.FindJoint("lhumerus");
  EXPECT_LT(clip.frames[1].rotation[humerus].angularDistance(Eigen::Quaterniond(about_y)), 1e-9);
  // Bones that the frame does not list keep their rest direction.
  EXPECT_LT((Position(clip, 1, "lowerback_end") - (root + Vector3d(0, 0, 5))).norm(), 1e-12);
}

TEST(AsfAmcTest, SingleChildRotationMovesTheTipAnalytically) {
  // lradius axis (0 45 0 XYZ): local x is world (cos 45, 0, -sin 45). `rx 60`
  // turns the forearm 60 degrees about that axis, about the elbow.
  const MocapClip clip = Parse();
  const Vector3d elbow = Vector3d(1, 2, 3) + Vector3d(10, 0, 0);
  const Vector3d axis(std::sqrt(0.5), 0, -std::sqrt(0.5));
  const Vector3d tip = elbow + AngleAxisd(60 * kDeg, axis) * Vector3d(0, -8, 0);
  EXPECT_LT((Position(clip, 2, "lradius") - elbow).norm(), 1e-9);
  EXPECT_LT((Position(clip, 2, "lradius_end") - tip).norm(), 1e-9);
  // The forearm's length is kept.
  EXPECT_NEAR((Position(clip, 2, "lradius_end") - elbow).norm(), 8, 1e-9);
  const int end = clip.FindJoint("lradius_end");
  EXPECT_LT(
      clip.frames[2].rotation[end].angularDistance(Eigen::Quaterniond(AngleAxisd(60 * kDeg, axis))),
      1e-9);
}

TEST(AsfAmcTest, RootTranslationAndRotation) {
  // Frame 4: root at position + (0.5, -1, 2), turned 90 degrees about z.
  const MocapClip clip = Parse();
  const Vector3d root = Vector3d(1, 2, 3) + Vector3d(0.5, -1, 2);
  const Matrix3d turn = AngleAxisd(90 * kDeg, Vector3d::UnitZ()).toRotationMatrix();
  EXPECT_LT((Position(clip, 3, "root") - root).norm(), 1e-12);
  EXPECT_LT((Position(clip, 3, "lradius") - (root + turn * Vector3d(10, 0, 0))).norm(), 1e-9);
  EXPECT_LT((Position(clip, 3, "lradius_end") - (root + turn * Vector3d(10, -8, 0))).norm(), 1e-9);
  EXPECT_LT((Position(clip, 3, "lowerback_end") - (root + Vector3d(0, 0, 5))).norm(), 1e-9);
}

TEST(AsfAmcTest, RootOrderAndRadians) {
  // The same frame 4 with the root's channels in another order and the AMC in
  // radians.
  const std::string asf = Replace(kAsf, "order TX TY TZ RX RY RZ", "order RZ RX RY TX TY TZ");
  const std::string amc =
      "# r\n:FULLY-SPECIFIED\n:RADIANS\n1\nroot " + Fmt(std::numbers::pi / 2) + " 0 0 0.5 -1 2\n";
  const MocapClip clip = Parse(asf, amc);
  const MocapClip reference = Parse();
  ASSERT_EQ(clip.frames.size(), 1u);
  for (size_t j = 0; j < clip.joint_names.size(); ++j) {
    EXPECT_LT((clip.frames[0].position[j] - reference.frames[3].position[j]).norm(), 1e-9)
        << clip.joint_names[j];
  }
}

TEST(AsfAmcTest, GeneralAxisOrderAndDofOrder) {
  // axis "10 20 30 ZYX": C = Rx(10)·Ry(20)·Rz(30) (Z applied first); dof
  // "rz rx ry" with values (a, b, c): M = Ry(c)·Rx(b)·Rz(a) (first listed
  // applied first); the bone turns by C·M·C⁻¹.
  std::string asf = Replace(kAsf, "axis 0 0 90  XYZ", "axis 10 20 30 ZYX");
  asf = Replace(asf, "dof rx ry rz", "dof rz rx ry");
  const std::string amc = "1\nlhumerus 25 -40 70\n";
  const Matrix3d c =
      (AngleAxisd(10 * kDeg, Vector3d::UnitX()) * AngleAxisd(20 * kDeg, Vector3d::UnitY()) *
       AngleAxisd(30 * kDeg, Vector3d::UnitZ()))
          .toRotationMatrix();
  const Matrix3d m =
      (AngleAxisd(70 * kDeg, Vector3d::UnitY()) * AngleAxisd(-40 * kDeg, Vector3d::UnitX()) *
       AngleAxisd(25 * kDeg, Vector3d::UnitZ()))
          .toRotationMatrix();
  const Matrix3d w = c * m * c.transpose();
  const MocapClip clip = Parse(asf, amc);
  const Vector3d root(1, 2, 3);
  EXPECT_LT((Position(clip, 0, "lradius") - (root + w * Vector3d(10, 0, 0))).norm(), 1e-9);
  EXPECT_LT((Position(clip, 0, "lradius_end") - (root + w * Vector3d(10, -8, 0))).norm(), 1e-9);
}

TEST(AsfAmcTest, AsfAnglesInRadians) {
  std::string asf = Replace(kAsf, "angle deg", "angle rad");
  asf = Replace(asf, "axis 0 0 90  XYZ", "axis 0 0 " + Fmt(std::numbers::pi / 2) + " XYZ");
  asf = Replace(asf, "axis 0 45 0 XYZ", "axis 0 " + Fmt(std::numbers::pi / 4) + " 0 XYZ");
  const MocapClip clip = Parse(asf);
  const MocapClip reference = Parse();
  for (size_t f = 0; f < clip.frames.size(); ++f) {
    for (size_t j = 0; j < clip.joint_names.size(); ++j) {
      EXPECT_LT((clip.frames[f].position[j] - reference.frames[f].position[j]).norm(), 1e-9);
    }
  }
}

TEST(AsfAmcTest, CrlfAndTabsParseIdentically) {
  const std::string asf = Crlf(kAsf);
  const std::string amc = Crlf(kAmc);
  const MocapClip a = Parse();
  const MocapClip b = Parse(asf, amc);
  EXPECT_EQ(a.joint_names, b.joint_names);
  EXPECT_EQ(a.parent, b.parent);
  EXPECT_EQ(a.metres_per_unit, b.metres_per_unit);
  EXPECT_EQ(a.rest_position, b.rest_position);
  ASSERT_EQ(a.frames.size(), b.frames.size());
  for (size_t f = 0; f < a.frames.size(); ++f) {
    EXPECT_EQ(a.frames[f].position, b.frames[f].position);
    for (size_t j = 0; j < a.joint_names.size(); ++j) {
      EXPECT_EQ(a.frames[f].rotation[j].coeffs(), b.frames[f].rotation[j].coeffs());
    }
  }
  // Line numbers count CRLF lines the same.
  ExpectError(asf, Crlf(Replace(kAmc, "lradius 60", "lradius 60 1")), "dir/test_01.amc",
              LineOf(kAmc, "lradius 60"), "has 2 values");
}

TEST(AsfAmcTest, LoadsFilesAndReportsMissingOnes) {
  const auto dir = std::filesystem::temp_directory_path() / "irbench_asf_amc_test";
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "07.asf", std::ios::binary) << kAsf;
  std::ofstream(dir / "07_03.amc", std::ios::binary) << kAmc;
  const MocapClip clip = LoadAsfAmc(dir / "07.asf", dir / "07_03.amc");
  EXPECT_EQ(clip.name, "07_03");
  EXPECT_EQ(clip.frames.size(), 4u);
  try {
    LoadAsfAmc(dir / "missing.asf", dir / "07_03.amc");
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "file");
    EXPECT_EQ(e.file(), (dir / "missing.asf").string());
  }
  try {
    LoadAsfAmc(dir / "07.asf", dir / "missing.amc");
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "file");
    EXPECT_EQ(e.file(), (dir / "missing.amc").string());
  }
  std::filesystem::remove_all(dir);
}

TEST(AsfAmcTest, AmcErrorsNameTheLine) {
  const std::string amc_file = "dir/test_01.amc";
  ExpectError(kAsf, Replace(kAmc, "lradius 60", "lfoo 60"), amc_file, LineOf(kAmc, "lradius 60"),
              "bone 'lfoo' is not in test.asf");
  ExpectError(kAsf, Replace(kAmc, "lhumerus 30 0 0", "lhumerus 30 0"), amc_file,
              LineOf(kAmc, "lhumerus 30 0 0"), "has 2 values");
  ExpectError(kAsf, Replace(kAmc, "lhumerus 30 0 0", "lhumerus 30 abc 0"), amc_file,
              LineOf(kAmc, "lhumerus 30 0 0"), "'abc' is not a number");
  ExpectError(kAsf, Replace(kAmc, "lradius 60", "lradius nan"), amc_file,
              LineOf(kAmc, "lradius 60"), "not finite");
  ExpectError(kAsf, Replace(kAmc, "lradius 60", "lradius -inf"), amc_file,
              LineOf(kAmc, "lradius 60"), "not finite");
  ExpectError(kAsf, Replace(kAmc, "root 0.5 -1 2 0 0 90", "root 0.5 -1 2 0 0"), amc_file,
              LineOf(kAmc, "root 0.5 -1 2 0 0 90"), "has 5 values");
  ExpectError(kAsf, Replace(kAmc, "lradius 60", "lradius 60\nlradius 1"), amc_file,
              LineOf(kAmc, "lradius 60") + 1, "listed twice");
  ExpectError(kAsf, Replace(kAmc, "\n3\n", "\n5\n"), amc_file, LineOf(kAmc, "\n3\n") + 1,
              "does not follow frame 2");
  ExpectError(kAsf, Replace(kAmc, ":DEGREES", ":GRADS"), amc_file, LineOf(kAmc, ":DEGREES"),
              "unknown AMC keyword");
  ExpectError(kAsf, "# nothing\n:FULLY-SPECIFIED\n:DEGREES\n", amc_file, 3, "no frames");
  ExpectError(kAsf, ":DEGREES\nroot 0 0 0 0 0 0\n", amc_file, 2, "expected a frame number");
}

TEST(AsfAmcTest, AsfErrorsNameTheLine) {
  const std::string asf_file = "test.asf";
  ExpectError(Replace(kAsf, "lhumerus lradius", "lhumerus lfoo"), kAmc, asf_file,
              LineOf(kAsf, "lhumerus lradius"), "bone 'lfoo' in :hierarchy is not defined");
  ExpectError(Replace(kAsf, "root lhumerus lowerback", "rooot lhumerus lowerback"), kAmc, asf_file,
              LineOf(kAsf, "root lhumerus lowerback"), "bone 'rooot'");
  // A bone without direction or length: the error names its `begin` line.
  const int lradius_begin = LineOf(kAsf, "id 2") - 1;
  ExpectError(Replace(kAsf, "direction 0 -1 0\n", ""), kAmc, asf_file, lradius_begin,
              "bone 'lradius' has no direction");
  ExpectError(Replace(kAsf, "length 8\n", ""), kAmc, asf_file, lradius_begin,
              "bone 'lradius' has no length");
  ExpectError(Replace(kAsf, "axis 0 45 0 XYZ", "axis 0 45 0 XYW"), kAmc, asf_file,
              LineOf(kAsf, "axis 0 45 0 XYZ"), "unknown axis order letter 'W'");
  ExpectError(Replace(kAsf, "axis XYZ", "axis XQZ"), kAmc, asf_file, LineOf(kAsf, "axis XYZ"),
              "unknown axis order letter 'Q'");
  ExpectError(Replace(kAsf, "axis 0 45 0 XYZ", "axis 0 4x5 0 XYZ"), kAmc, asf_file,
              LineOf(kAsf, "axis 0 45 0 XYZ"), "'4x5' is not a number");
  ExpectError(Replace(kAsf, "dof rx\n", "dof rx rw\n"), kAmc, asf_file, LineOf(kAsf, "dof rx\n"),
              "unknown dof 'rw'");
  ExpectError(Replace(kAsf, "limits (-10.0 170.0)", "limits (-10.0 170.0) (0 1)"), kAmc, asf_file,
              LineOf(kAsf, "limits (-10.0 170.0)"), "2 limits for 1 dofs");
  ExpectError(Replace(kAsf, "name lradius", "name lhumerus"), kAmc, asf_file,
              LineOf(kAsf, "name lradius"), "used twice");
  ExpectError(Replace(kAsf, "length 0.45", "length nan"), kAmc, asf_file,
              LineOf(kAsf, "length 0.45"), "not finite");
  ExpectError(Replace(kAsf, "    root lhumerus lowerback\n", "    root lowerback\n"), kAmc,
              asf_file, LineOf(kAsf, "id 1") - 1, "'lhumerus' is not connected to root");

  // Missing sections: the error names the file's last line.
  const std::string head = kAsf;
  const std::string no_bonedata = head.substr(0, head.find(":bonedata"));
  ExpectError(no_bonedata, kAmc, asf_file, LineOf(kAsf, ":bonedata") - 1, "no :bonedata");
  const std::string no_hierarchy = head.substr(0, head.find(":hierarchy"));
  ExpectError(no_hierarchy, kAmc, asf_file, LineOf(kAsf, ":hierarchy") - 1, "no :hierarchy");
  const std::string open_bone = head.substr(0, head.find("  end\n  begin"));
  ExpectError(open_bone, kAmc, asf_file, LineOf(kAsf, "  end\n  begin") - 1,
              "inside the bone block begun at line " + std::to_string(LineOf(kAsf, "id 1") - 1));
}

// Issue 27.3: two bones with one name make the skeleton ambiguous; so does a
// bone named like another leaf bone's tip joint ("<bone>_end").
TEST(AsfAmcTest, DuplicateBoneNamesAreRefused) {
  const std::string asf_file = "test.asf";
  ExpectError(Replace(kAsf, "name lradius", "name lhumerus"), kAmc, asf_file,
              LineOf(kAsf, "name lradius"), "bone name 'lhumerus' used twice");
  ExpectError(Replace(kAsf, "name lowerback", "name root"), kAmc, asf_file,
              LineOf(kAsf, "name lowerback"), "'root' used twice");
  // lradius is a leaf: its tip is the clip joint "lradius_end".
  const std::string tip = ReplaceAll(kAsf, "lowerback", "lradius_end");
  ExpectError(tip, kAmc, asf_file, LineOf(kAsf, "id 3") - 1,
              "bone name 'lradius_end' is also the name of bone 'lradius''s tip joint");
}

// Issue 27.3: AMC and ASF values that are not finite or physically absurd
// (a rotation of -1e308 degrees wrote 'nan' into the truth) are refused
// naming the file and line.
TEST(AsfAmcTest, AbsurdValuesAreRefused) {
  const std::string amc_file = "dir/test_01.amc", asf_file = "test.asf";
  const int lradius = LineOf(kAmc, "lradius 60");
  ExpectError(kAsf, Replace(kAmc, "lradius 60", "lradius -1e308"), amc_file, lradius,
              "rotation '-1e308' is beyond +-1e+06 degrees");
  ExpectError(kAsf, Replace(kAmc, "lradius 60", "lradius 1e400"), amc_file, lradius, "rotation");
  ExpectError(kAsf, Replace(kAmc, "root 0.5 -1 2 0 0 90", "root 0.5 -1e6 2 0 0 90"), amc_file,
              LineOf(kAmc, "root 0.5 -1 2 0 0 90"), "beyond +-100000 file units");
  // In radians the limit is the same angle: 20000 rad is about 1.15e6 degrees.
  const std::string radians = Replace(kAmc, ":DEGREES", ":RADIANS");
  ExpectError(kAsf, Replace(radians, "lradius 60", "lradius 20000"), amc_file, lradius,
              "beyond +-17453");
  EXPECT_NO_THROW(Parse(kAsf, Replace(radians, "lradius 60", "lradius 17000")));
  EXPECT_NO_THROW(Parse(kAsf, Replace(kAmc, "lradius 60", "lradius -720")));
  // The skeleton's numbers.
  ExpectError(Replace(kAsf, "length 8\n", "length 1e300\n"), kAmc, asf_file, LineOf(kAsf, "length 8\n"),
              "length '1e300' is beyond");
  ExpectError(Replace(kAsf, "position 1 2 3", "position 1 -2e5 3"), kAmc, asf_file,
              LineOf(kAsf, "position 1 2 3"), "position '-2e5'");
  ExpectError(Replace(kAsf, "axis 0 45 0 XYZ", "axis 0 4.5e7 0 XYZ"), kAmc, asf_file,
              LineOf(kAsf, "axis 0 45 0 XYZ"), "axis angle '4.5e7'");
  ExpectError(Replace(kAsf, "direction 0 -1 0", "direction 0 -1e300 0"), kAmc, asf_file,
              LineOf(kAsf, "direction 0 -1 0"), "direction");
  ExpectError(Replace(kAsf, "length 0.45", "length 1e-300"), kAmc, asf_file,
              LineOf(kAsf, "length 0.45"), "length unit must be in");
}

TEST(AsfAmcTest, TranslationAndLengthDofs) {
  // `tx` moves the bone's start along its local x (world y for lhumerus) before
  // its rotation, as in the CMU viewer; `l` adds to the length.
  const std::string asf = Replace(kAsf,
                                  "dof rx ry rz\n     limits (-90.0 90.0)\n"
                                  "            (-90.0 90.0)\n            (-inf inf)\n",
                                  "dof tx rz l\n");
  const MocapClip clip = Parse(asf, "1\nlhumerus 2 90 1\n");
  const Vector3d root(1, 2, 3);
  const Vector3d start = root + Vector3d(0, 2, 0);
  EXPECT_LT((Position(clip, 0, "lhumerus") - start).norm(), 1e-9);
  EXPECT_LT((Position(clip, 0, "lradius") - (start + Vector3d(0, 11, 0))).norm(), 1e-9);
}

}  // namespace
}  // namespace irbench
