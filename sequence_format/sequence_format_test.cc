#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>

#include "common/error.h"
#include "sequence_format/calibration.h"
#include "sequence_format/manifest.h"
#include "sequence_format/screens.h"

namespace irbench {
namespace {
namespace fs = std::filesystem;

class SequenceFormatTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("irbench_sequence_format_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_ / "calib");
  }
  void TearDown() override { fs::remove_all(dir_); }

  static std::vector<Camera> Cameras() {
    std::vector<Camera> cameras(2);
    cameras[0].name = "front";
    cameras[0].fx = 260.5, cameras[0].fy = 261.25, cameras[0].cx = 160.1, cameras[0].cy = 119.7;
    cameras[0].dist = {-0.2, 0.04, 0.001, -0.002, 0.003};
    cameras[0].cam_from_world = *LookAt({0.3, -3.1, 2.2}, {0, 0, 1}, Eigen::Vector3d::UnitZ());
    cameras[1].name = "overhead";
    cameras[1].width = 640, cameras[1].height = 480;
    cameras[1].fx = cameras[1].fy = 400, cameras[1].cx = 319.5, cameras[1].cy = 239.5;
    cameras[1].cam_from_world = *LookAt({0, 0.1, 3.5}, {0, 0, 0}, Eigen::Vector3d::UnitY());
    return cameras;
  }
  std::string ReadErrorField() {
    try {
      ReadCalibration(dir_);
    } catch (const InputError& e) {
      return e.field();
    }
    return "(no error)";
  }
  fs::path dir_;
};

// What the writer writes, the reader reads back exactly, and OpenCV's own
// FileStorage finds the EasyMocap keys with a Rodrigues vector that matches Rot_.
TEST_F(SequenceFormatTest, CalibrationRoundTripsAndOpenCvReadsIt) {
  const std::vector<Camera> cameras = Cameras();
  const std::vector<CameraTiming> timing = {{25, 8}, {30, 10}};
  WriteCalibration(dir_, cameras, timing,
                   {nlohmann::json{{"preset", "clean"}}, nlohmann::json{{"preset", "thesis"}}});
  const Calibration calibration = ReadCalibration(dir_);
  const std::vector<Camera>& read = calibration.cameras;
  ASSERT_EQ(calibration.timing.size(), 2u);
  ASSERT_EQ(read.size(), 2u);
  for (size_t i = 0; i < 2; ++i) {
    EXPECT_EQ(read[i].name, cameras[i].name);
    EXPECT_EQ(read[i].width, cameras[i].width);
    EXPECT_EQ(read[i].height, cameras[i].height);
    EXPECT_DOUBLE_EQ(read[i].fx, cameras[i].fx);
    EXPECT_DOUBLE_EQ(read[i].cy, cameras[i].cy);
    EXPECT_EQ(read[i].dist, cameras[i].dist);
    EXPECT_DOUBLE_EQ(calibration.timing[i].fps, timing[i].fps);
    EXPECT_DOUBLE_EQ(calibration.timing[i].exposure_ms, timing[i].exposure_ms);
    EXPECT_LT((read[i].cam_from_world.matrix() - cameras[i].cam_from_world.matrix())
                  .cwiseAbs()
                  .maxCoeff(),
              1e-12);
  }
  cv::FileStorage extri((dir_ / "calib/extri.yml").string(), cv::FileStorage::READ);
  cv::Mat rvec, rot, rot_from_rvec;
  extri["R_front"] >> rvec;
  extri["Rot_front"] >> rot;
  cv::Rodrigues(rvec, rot_from_rvec);
  EXPECT_LT(cv::norm(rot - rot_from_rvec, cv::NORM_INF), 1e-9);
}

TEST_F(SequenceFormatTest, CalibrationErrorsNameTheKey) {
  std::vector<Camera> cameras = Cameras();
  WriteCalibration(dir_, cameras, {{}, {}}, {nlohmann::json::object(), nlohmann::json::object()});
  // A camera in the YAML files but not in cameras.json.
  std::ofstream(dir_ / "calib/cameras.json") << R"({"format": "irbench.cameras/1", "cameras": [
      {"name": "front", "width": 320, "height": 240, "fps": 25}]})";
  EXPECT_EQ(ReadErrorField(), "cameras");
  // A focal length of zero.
  cameras[1].fx = 0;
  WriteCalibration(dir_, cameras, {{}, {}}, {nlohmann::json::object(), nlohmann::json::object()});
  EXPECT_EQ(ReadErrorField(), "K_overhead");
  fs::remove(dir_ / "calib/extri.yml");
  try {
    ReadCalibration(dir_);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("extri.yml"), std::string::npos) << e.what();
  }
}

// A matrix whose declared size is garbage is refused before OpenCV allocates
// it (fuzz/calibration_fuzz found `cols:` read as 0xc00000030: 48 GiB).
TEST_F(SequenceFormatTest, AMatrixOfAbsurdSizeIsRefusedBeforeAllocating) {
  WriteCalibration(dir_, Cameras(), {{}, {}}, {nlohmann::json::object(), nlohmann::json::object()});
  std::ifstream in(dir_ / "calib/extri.yml");
  const std::string extri((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const size_t at = extri.find("cols: 3", extri.find("Rot_overhead"));
  ASSERT_NE(at, std::string::npos) << extri;
  for (const char* cols : {"cols: 1610612742", "cols: 4", "cols: x", "cols: -3"}) {
    std::string text = extri;
    text.replace(at, std::string("cols: 3").size(), cols);
    std::ofstream(dir_ / "calib/extri.yml") << text;
    EXPECT_EQ(ReadErrorField(), "Rot_overhead") << cols;
  }
}

// OpenCV 4.6's YAML parser never returns on some malformed files (found by
// fuzz/calibration_fuzz); files not in OpenCV's own layout are refused first.
TEST_F(SequenceFormatTest, YamlOutsideOpenCvsLayoutIsRefusedBeforeParsing) {
  WriteCalibration(dir_, Cameras(), {{}, {}}, {nlohmann::json::object(), nlohmann::json::object()});
  for (const std::string& text :
       {std::string("%YAML:1.0\n---%YAML:1.0\n\nna---\nnme"), std::string("%YAML:1.0\n s: 3\n--\n-"),  // hangs
        std::string("names: [a]\n"), std::string("%YAML:1.0\n---\n%TAG ! x\n"),
        std::string("%YAML:1.0\nnames:\n   front_left\n"), std::string("%YAML:1.0\nK: !!opencv-matrix\n   foo: 1\n"),
        std::string("%YAML:1.0\nK: !!opencv-matrix\n   data: [ 1, 2,\n"), std::string("%YAML:1.0\nnames:\n   - k\xc3\xbc\n")}) {
    std::ofstream(dir_ / "calib/intri.yml") << text;
    try {
      ReadCalibration(dir_);
      ADD_FAILURE() << "no error for " << text;
    } catch (const InputError& e) {
      EXPECT_EQ(fs::path(e.file()).filename(), "intri.yml") << e.what();
    }
  }
}

// Issue 27.3: the tracker reads camera names from calib/intri.yml; names
// outside [A-Za-z0-9_-] (1-64 characters, not starting with '-') are refused
// naming the file and the field.
TEST_F(SequenceFormatTest, UnsafeCameraNamesAreRefused) {
  WriteCalibration(dir_, Cameras(), {{}, {}}, {nlohmann::json::object(), nlohmann::json::object()});
  std::ifstream in(dir_ / "calib/intri.yml");
  const std::string intri((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const size_t at = intri.find("- overhead");
  ASSERT_NE(at, std::string::npos) << intri;
  for (const std::string& bad :
       {std::string("\"..\""), std::string("\".\""), std::string(300, 'a'), std::string("kamera_\u00fc"),
        std::string("\"-x\""), std::string("\"a/b\"")}) {
    std::string text = intri;
    text.replace(at, std::string("- overhead").size(), "- " + bad);
    std::ofstream(dir_ / "calib/intri.yml") << text;
    try {
      ReadCalibration(dir_);
      ADD_FAILURE() << "no error for " << bad;
    } catch (const InputError& e) {
      EXPECT_EQ(e.field(), "names[1]") << bad << ": " << e.what();
      EXPECT_NE(e.file().find("intri.yml"), std::string::npos) << e.what();
    }
  }
  EXPECT_EQ(CameraNameProblem("front_left-2"), "");
  EXPECT_NE(CameraNameProblem(std::string(65, 'c')), "");
}

TEST_F(SequenceFormatTest, ScreensRoundTripWithTheirTargets) {
  ScreenSurface wall;
  wall.name = "wall";
  wall.origin = {-1.5, 3.48, 0.6};
  wall.width = 3.0, wall.height = 1.9;
  wall.targets = {{"center", {1.5, 1.0}}, {"left", {0.25, 1.2}}};
  ScreenSurface dome;
  dome.name = "dome";
  dome.kind = ScreenSurface::Kind::kCylinder;
  dome.radius = 3.2, dome.z0 = 0.1, dome.z1 = 2.5;
  EXPECT_TRUE(ReadScreens(dir_).empty());  // no file: no screens
  WriteScreens(dir_, "lab", {wall, dome});
  const std::vector<ScreenSurface> read = ReadScreens(dir_);
  ASSERT_EQ(read.size(), 2u);
  EXPECT_EQ(read[0].name, "wall");
  EXPECT_EQ(read[0].targets, wall.targets);
  EXPECT_EQ(read[1].kind, ScreenSurface::Kind::kCylinder);
  EXPECT_DOUBLE_EQ(read[1].radius, 3.2);
  EXPECT_DOUBLE_EQ(read[1].Size().x(), dome.Size().x());
  // The world point written beside each target is the screen's PointAt.
  const JsonNode root = ParseJsonFile((dir_ / kScreensFile).string());
  const Eigen::Vector3d world = root["screens"][0]["targets"]["center"]["world"].Vec3();
  EXPECT_LT((world - wall.PointAt({1.5, 1.0})).norm(), 1e-12);
  // A target off the screen is refused, naming it.
  std::ofstream(dir_ / kScreensFile)
      << R"({"format": "irbench.screens/1", "scene": "lab", "screens": [
      {"name": "wall", "type": "plane", "origin": [0, 3, 0], "right": [1, 0, 0], "up": [0, 0, 1],
       "width": 2, "height": 1, "targets": {"far": {"screen": [2.5, 0.5]}}}]})";
  try {
    ReadScreens(dir_);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "screens[0].targets.far");
  }
}

TEST_F(SequenceFormatTest, ManifestWrittenIsRead) {
  EXPECT_FALSE(HasManifest(dir_));
  EXPECT_THROW(ReadManifest(dir_), InputError);
  const nlohmann::json m = {{"format", kSequenceFormat},
                            {"seed", 7},
                            {"fps", 30.0},
                            {"frame_count", 12},
                            {"cameras", {"a", "b"}},
                            {"joints", {"root", "neck"}},
                            {"scene", {{"name", "theater4"}, {"file", "scenes/theater4.json"}}},
                            {"avatar", {{"name", "p1"}}},
                            {"sensor", "thesis"}};
  WriteManifest(dir_, m);
  EXPECT_TRUE(HasManifest(dir_));
  const Manifest read = ReadManifest(dir_);
  EXPECT_EQ(read.seed, 7u);
  EXPECT_EQ(read.frame_count, 12);
  EXPECT_EQ(read.cameras, (std::vector<std::string>{"a", "b"}));
  EXPECT_EQ(read.scene, "theater4");
  EXPECT_EQ(read.avatar, "p1");
  EXPECT_EQ(read.sensor, "thesis");
  EXPECT_EQ(read.rig, "");
  std::ofstream(dir_ / kManifestFile) << R"({"format": "irbench.sequence/0"})";
  EXPECT_THROW(ReadManifest(dir_), InputError);
}

}  // namespace
}  // namespace irbench
