#include "geometry/camera.h"

#include <gtest/gtest.h>

#include <opencv2/calib3d.hpp>
#include <vector>

namespace irbench {
namespace {

TEST(CameraTest, LookAtPutsTargetAtPrincipalPointAndUpUp) {
  Camera cam;
  cam.fx = cam.fy = 300;
  cam.cx = 160;
  cam.cy = 120;
  const Eigen::Vector3d position(2, -3, 1.5), target(0, 0, 1);
  cam.cam_from_world = *LookAt(position, target, Eigen::Vector3d::UnitZ());
  const Eigen::Vector2d center = cam.Project(target);
  EXPECT_NEAR(center.x(), 160, 1e-9);
  EXPECT_NEAR(center.y(), 120, 1e-9);
  // A point above the target appears higher in the image (smaller v).
  EXPECT_LT(cam.Project(target + Eigen::Vector3d(0, 0, 0.5)).y(), 120);
  EXPECT_TRUE((cam.CenterInWorld() - position).norm() < 1e-12);
  EXPECT_FALSE(LookAt(position, position, Eigen::Vector3d::UnitZ()).has_value());
  EXPECT_FALSE(LookAt({0, 0, 3}, {0, 0, 0}, Eigen::Vector3d::UnitZ()).has_value());
}

TEST(CameraTest, ScaledKeepsTheRays) {
  Camera cam;
  cam.fx = 260, cam.fy = 261, cam.cx = 160.8, cam.cy = 118.7;
  cam.cam_from_world = *LookAt({0, 4, 1}, {0, 0, 1}, Eigen::Vector3d::UnitZ());
  const Camera big = cam.Scaled(2.0);
  const Eigen::Vector3d p(0.3, 0.2, 1.4);
  const Eigen::Vector2d a = cam.Project(p), b = big.Project(p);
  // Pixel centres: (u + 0.5) * 2 - 0.5.
  EXPECT_NEAR(b.x(), (a.x() + 0.5) * 2 - 0.5, 1e-9);
  EXPECT_NEAR(b.y(), (a.y() + 0.5) * 2 - 0.5, 1e-9);
}

Camera DistortedCamera() {
  Camera cam;
  cam.fx = 262.5, cam.fy = 263.1, cam.cx = 161.2, cam.cy = 118.4;
  cam.dist = {-0.21, 0.05, 0.0012, -0.0008, -0.004};
  cam.cam_from_world = *LookAt({2, -3, 2.2}, {0, 0, 1}, Eigen::Vector3d::UnitZ());
  return cam;
}

// Pixel -> normalised -> pixel is the identity, and UndistortPixel agrees with
// cv::undistortPoints on a grid over the image (and a little beyond).
TEST(CameraTest, UndistortPixelMatchesOpenCv) {
  const Camera cam = DistortedCamera();
  cv::Mat k = (cv::Mat_<double>(3, 3) << cam.fx, 0, cam.cx, 0, cam.fy, cam.cy, 0, 0, 1);
  cv::Mat dist =
      (cv::Mat_<double>(1, 5) << cam.dist[0], cam.dist[1], cam.dist[2], cam.dist[3], cam.dist[4]);
  std::vector<cv::Point2d> pixels, ours;
  for (double u = -0.5; u <= cam.width; u += cam.width / 10.0) {
    for (double v = -0.5; v <= cam.height; v += cam.height / 8.0) {
      const Eigen::Vector2d px(u, v);
      const Eigen::Vector2d back = cam.NormalisedToPixel(cam.PixelToNormalised(px));
      EXPECT_NEAR((back - px).norm(), 0, 1e-12);
      const auto x_u = cam.UndistortPixel(px);
      ASSERT_TRUE(x_u.has_value());
      EXPECT_NEAR((cam.DistortToPixel(*x_u) - px).norm(), 0, 1e-9);
      pixels.emplace_back(u, v);
      ours.emplace_back(x_u->x(), x_u->y());
    }
  }
  std::vector<cv::Point2d> theirs;
  cv::undistortPoints(
      pixels, theirs, k, dist, cv::noArray(), cv::noArray(),
      cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 100, 1e-14));
  for (size_t i = 0; i < ours.size(); ++i) {
    EXPECT_NEAR(ours[i].x, theirs[i].x, 1e-7) << i;
    EXPECT_NEAR(ours[i].y, theirs[i].y, 1e-7) << i;
  }
}

// The ray through a pixel projects back onto that pixel, and Project equals
// cv::projectPoints.
TEST(CameraTest, PixelRayProjectsBackAndProjectMatchesOpenCv) {
  const Camera cam = DistortedCamera();
  const Eigen::Vector3d center = cam.CenterInWorld();
  for (double u = 10; u < cam.width; u += 50) {
    for (double v = 10; v < cam.height; v += 40) {
      const auto ray = cam.PixelRayInWorld({u, v});
      ASSERT_TRUE(ray.has_value());
      const Eigen::Vector2d px = cam.Project(center + 2.5 * *ray);
      EXPECT_NEAR(px.x(), u, 1e-9);
      EXPECT_NEAR(px.y(), v, 1e-9);
    }
  }
  cv::Mat k = (cv::Mat_<double>(3, 3) << cam.fx, 0, cam.cx, 0, cam.fy, cam.cy, 0, 0, 1);
  cv::Mat dist =
      (cv::Mat_<double>(1, 5) << cam.dist[0], cam.dist[1], cam.dist[2], cam.dist[3], cam.dist[4]);
  cv::Mat r(3, 3, CV_64F), rvec, tvec(3, 1, CV_64F);
  for (int a = 0; a < 3; ++a) {
    tvec.at<double>(a) = cam.cam_from_world.translation()(a);
    for (int b = 0; b < 3; ++b) r.at<double>(a, b) = cam.cam_from_world.linear()(a, b);
  }
  cv::Rodrigues(r, rvec);
  const std::vector<cv::Point3d> points = {{0, 0, 1}, {0.4, -0.3, 1.7}, {-0.6, 0.5, 0.2}};
  std::vector<cv::Point2d> theirs;
  cv::projectPoints(points, rvec, tvec, k, dist, theirs);
  for (size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector2d ours = cam.Project({points[i].x, points[i].y, points[i].z});
    EXPECT_NEAR(ours.x(), theirs[i].x, 1e-9);
    EXPECT_NEAR(ours.y(), theirs[i].y, 1e-9);
  }
}

}  // namespace
}  // namespace irbench
