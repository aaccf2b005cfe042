#include "sim/camera/rig.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <opencv2/calib3d.hpp>
#include <random>
#include <unistd.h>

#include "common/error.h"
#include "geometry/camera.h"

namespace irbench {
namespace {

std::vector<std::filesystem::path> AllRigFiles() {
  std::vector<std::filesystem::path> files;
  for (const auto& e : std::filesystem::directory_iterator(std::string(IRBENCH_SOURCE_DIR) + "/rigs")) {
    if (e.path().extension() == ".json") files.push_back(e.path());
  }
  return files;
}

// Our projection against OpenCV's, for random points in front of and around
// every camera of every rig.
TEST(RigTest, ProjectMatchesOpenCvOnEveryRig) {
  const auto files = AllRigFiles();
  ASSERT_GE(files.size(), 4u);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> coord(-3.0, 3.0), height(0.0, 2.5);
  for (const auto& file : files) {
    const Rig rig = LoadRig(file);
    for (const Camera& cam : rig.cameras) {
      std::vector<cv::Point3d> points;
      for (int i = 0; i < 200; ++i) points.emplace_back(coord(rng), coord(rng), height(rng));
      cv::Mat rvec, tvec = (cv::Mat_<double>(3, 1) << cam.cam_from_world.translation().x(),
                            cam.cam_from_world.translation().y(), cam.cam_from_world.translation().z());
      cv::Mat rot(3, 3, CV_64F);
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) rot.at<double>(r, c) = cam.cam_from_world.linear()(r, c);
      cv::Rodrigues(rot, rvec);
      cv::Mat k = (cv::Mat_<double>(3, 3) << cam.fx, 0, cam.cx, 0, cam.fy, cam.cy, 0, 0, 1);
      cv::Mat dist(1, 5, CV_64F, const_cast<double*>(cam.dist.data()));
      std::vector<cv::Point2d> expected;
      cv::projectPoints(points, rvec, tvec, k, dist, expected);
      for (size_t i = 0; i < points.size(); ++i) {
        const Eigen::Vector3d p_in_cam =
            cam.cam_from_world * Eigen::Vector3d(points[i].x, points[i].y, points[i].z);
        if (p_in_cam.z() < 0.2) continue;  // near the camera plane pixels explode
        const Eigen::Vector2d px = cam.Project({points[i].x, points[i].y, points[i].z});
        EXPECT_NEAR(px.x(), expected[i].x, 1e-6) << file << " " << cam.name;
        EXPECT_NEAR(px.y(), expected[i].y, 1e-6) << file << " " << cam.name;
      }
    }
  }
}

TEST(RigTest, UndistortInvertsDistortAcrossEveryRigsImage) {
  for (const auto& file : AllRigFiles()) {
    for (const Camera& cam : LoadRig(file).cameras) {
      for (double u = -0.5; u <= cam.width; u += cam.width / 16.0) {
        for (double v = -0.5; v <= cam.height; v += cam.height / 12.0) {
          const Eigen::Vector2d x_d((u - cam.cx) / cam.fx, (v - cam.cy) / cam.fy);
          const auto x_u = cam.Undistort(x_d);
          ASSERT_TRUE(x_u.has_value()) << cam.name;
          EXPECT_LT((cam.Distort(*x_u) - x_d).norm(), 1e-12);
        }
      }
    }
  }
}


class RigErrorTest : public ::testing::Test {
 protected:
  std::string Write(const std::string& text) {
    const auto path = std::filesystem::temp_directory_path() /
                      ("irbench_rig_" + std::to_string(::getpid()) + "_" + std::to_string(counter_++) + ".json");
    FILE* f = std::fopen(path.c_str(), "w");
    std::fputs(text.c_str(), f);
    std::fclose(f);
    return path.string();
  }
  std::string Camera(const std::string& fields) {
    return R"({"format": "irbench.rig/1", "cameras": [{"name": "c0", )" + fields + "}]}";
  }
  std::string ErrorOf(const std::string& text) {
    try {
      LoadRig(Write(text));
    } catch (const InputError& e) {
      return e.field();
    }
    return "(no error)";
  }
  int counter_ = 0;
  const std::string pose_ = R"("position": [0, 3, 1], "look_at": [0, 0, 1])";
  const std::string dist_ = R"("dist": [0, 0, 0, 0, 0])";
};

TEST_F(RigErrorTest, NamesTheField) {
  EXPECT_EQ(ErrorOf(Camera(R"("fx": 300, "fy": 300, "cx": 160, )" + dist_ + ", " + pose_)),
            "cameras[0].cy");
  EXPECT_EQ(ErrorOf(Camera(R"("fx": -300, "fy": 300, "cx": 160, "cy": 120, )" + dist_ + ", " + pose_)),
            "cameras[0].fx");
  EXPECT_EQ(ErrorOf(Camera(R"("fx": 300, "fy": 300, "cx": 160, "cy": 120, "dist": [0, 0], )" + pose_)),
            "cameras[0].dist");
  EXPECT_EQ(ErrorOf(Camera(R"("fx": 300, "fy": 300, "cx": 160, "cy": 120, "dist": [-3, 0, 0, 0, 0], )" + pose_)),
            "cameras[0].dist");
  EXPECT_EQ(ErrorOf(Camera(R"("fx": 300, "fy": 300, "cx": 160, "cy": 120, )" + dist_ +
                           R"(, "position": [0, 0, 3], "look_at": [0, 0, 0])")),
            "cameras[0].look_at");
  EXPECT_EQ(ErrorOf(Camera(R"("fx": 300, "fy": 300, "cx": 160, "cy": 120, "exposure_ms": 50, )" + dist_ + ", " + pose_)),
            "cameras[0].exposure_ms");
  EXPECT_EQ(ErrorOf(Camera(R"("fx": 300, "fy": 300, "cx": 160, "cy": 120, "fxx": 1, )" + dist_ + ", " + pose_)),
            "cameras[0].fxx");
  EXPECT_EQ(ErrorOf(R"({"format": "irbench.rig/1", "cameras": [)"), "line 1");
  EXPECT_EQ(ErrorOf(Camera(R"("fx": 300, "fy": 300, "cx": 160, "cy": 120, )" + dist_ + ", " + pose_)),
            "(no error)");
}

// The rig keeps each camera's "up" as written (+z when left out), and its
// image's up is that up with the view direction taken out.
TEST_F(RigErrorTest, EachCamerasUpIsKept) {
  const std::string intrinsics = R"("fx": 300, "fy": 300, "cx": 160, "cy": 120, )" + dist_ + ", " + pose_;
  const Rig rig = LoadRig(Write(R"({"format": "irbench.rig/1", "cameras": [{"name": "a", )" + intrinsics +
                                R"(}, {"name": "b", "up": [1, 0, 1], )" + intrinsics + "}]}"));
  ASSERT_EQ(rig.up.size(), 2u);
  EXPECT_EQ(rig.up[0], Eigen::Vector3d(0, 0, 1));
  EXPECT_EQ(rig.up[1], Eigen::Vector3d(1, 0, 1));
  // Camera b looks along -y: its image's up (-y_cam in the world) is the
  // written up's direction, the view's component being zero already.
  const Eigen::Vector3d image_up = -(rig.cameras[1].cam_from_world.linear().transpose() * Eigen::Vector3d::UnitY());
  EXPECT_NEAR((image_up - Eigen::Vector3d(1, 0, 1).normalized()).norm(), 0, 1e-9);
}

// Issue 27.3: camera names "..", ".", 300 characters or non-ASCII reached the
// file system and OpenCV (exit 1 with a raw message); only [A-Za-z0-9_-],
// 1-64 characters, not starting with '-', are accepted.
TEST_F(RigErrorTest, CameraNamesAreFromTheSafeSet) {
  const std::string rest = R"("fx": 300, "fy": 300, "cx": 160, "cy": 120, )" + dist_ + ", " + pose_;
  auto named = [&](const std::string& name) {
    return R"({"format": "irbench.rig/1", "cameras": [{"name": ")" + name + "\", " + rest + "}]}";
  };
  for (const std::string& bad : std::vector<std::string>{"..", ".", std::string(300, 'a'), std::string(65, 'b'), "kamera_\u00fc",
                                "cam\u00e9ra", "-front", "a b", "a/b", "a.b", "", "c$d", "a:b"}) {
    EXPECT_EQ(ErrorOf(named(bad)), "cameras[0].name") << bad;
  }
  for (const std::string& good : std::vector<std::string>{"front_left", "Cam-01", "c", std::string(64, 'z'), "_x", "0"}) {
    EXPECT_EQ(ErrorOf(named(good)), "(no error)") << good;
  }
}

// Issue 27.3: fx = 1e308 rendered black frames with exit 0; focal lengths,
// distortion and coordinates have physical ranges.
TEST_F(RigErrorTest, NumbersOutsidePhysicalRangesNameTheField) {
  const std::string pp = R"("cx": 160, "cy": 120, )";
  EXPECT_EQ(ErrorOf(Camera(R"("fx": 1e308, "fy": 300, )" + pp + dist_ + ", " + pose_)), "cameras[0].fx");
  EXPECT_EQ(ErrorOf(Camera(R"("fx": 32001, "fy": 300, )" + pp + dist_ + ", " + pose_)), "cameras[0].fx");
  EXPECT_EQ(ErrorOf(Camera(R"("fx": 300, "fy": 1e-300, )" + pp + dist_ + ", " + pose_)), "cameras[0].fy");
  EXPECT_EQ(ErrorOf(Camera(R"("fx": 300, "fy": 300, )" + pp + R"("dist": [0, 0, 1e300, 0, 0], )" + pose_)),
            "cameras[0].dist[2]");
  EXPECT_EQ(ErrorOf(Camera(R"("fx": 300, "fy": 300, )" + pp + dist_ +
                           R"(, "position": [0, 1e308, 1], "look_at": [0, 0, 1])")),
            "cameras[0].position[1]");
  EXPECT_EQ(ErrorOf(Camera(R"("fx": 300, "fy": 300, )" + pp + dist_ + ", " + pose_ + R"(, "up": [0, 0, 1e9])")),
            "cameras[0].up[2]");
  // The bounds themselves are fine: 100 x 320 and 0.01 x 240 px.
  EXPECT_EQ(ErrorOf(Camera(R"("fx": 32000, "fy": 2.4, )" + pp + dist_ + ", " + pose_)), "(no error)");
}

}  // namespace
}  // namespace irbench
