#include "tracker/body_model/ellipse_projection.h"

#include <gtest/gtest.h>

#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
#include <cstdio>
#include <random>

#include "sim/camera/rig.h"

namespace irbench {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;

// The rim points projected by OpenCV with the camera's full model, then
// undistorted to ideal pixels by OpenCV (iterated to convergence).
std::vector<Vector2d> OpenCvIdealPixels(const Camera& cam, const std::vector<Vector3d>& points) {
  std::vector<cv::Point3d> object;
  for (const Vector3d& p : points) object.emplace_back(p.x(), p.y(), p.z());
  cv::Mat rotation, rvec, tvec, K;
  const Eigen::Matrix3d r = cam.cam_from_world.linear();
  cv::eigen2cv(r, rotation);
  cv::Rodrigues(rotation, rvec);
  const Vector3d t = cam.cam_from_world.translation();
  tvec = (cv::Mat_<double>(3, 1) << t.x(), t.y(), t.z());
  cv::eigen2cv(cam.K(), K);
  const cv::Mat dist(1, 5, CV_64F, const_cast<double*>(cam.dist.data()));
  std::vector<cv::Point2d> distorted, ideal;
  cv::projectPoints(object, rvec, tvec, K, dist, distorted);
  cv::undistortPoints(distorted, ideal, K, dist, cv::noArray(), K,
                          cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 200, 1e-12));
  std::vector<Vector2d> out;
  for (const cv::Point2d& p : ideal) out.emplace_back(p.x, p.y);
  return out;
}

Ellipsoid RandomEllipsoid(std::mt19937& rng) {
  std::uniform_real_distribution<double> pos(-0.8, 0.8), height(0.1, 1.9), radius(0.02, 0.35), angle(-M_PI, M_PI);
  Ellipsoid e;
  e.center = Vector3d(pos(rng), pos(rng), height(rng));
  e.radii = Vector3d(radius(rng), radius(rng), radius(rng));
  e.world_from_segment = RotationZxy(angle(rng), angle(rng), angle(rng));
  return e;
}

// Issue 7's bar: rim points projected with cv::projectPoints lie within
// 0.05 px of the analytic conic, for every camera of the thesis rig
// (distortion included) and ellipsoids of body-segment sizes anywhere on the
// stage.
TEST(EllipseProjection, RimProjectsOntoTheAnalyticConicWithinFiveHundredthsOfAPixel) {
  const Rig rig = LoadRig(std::string(IRBENCH_SOURCE_DIR) + "/rigs/theater4.json");
  std::mt19937 rng(11);
  int checked = 0;
  double worst = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const Ellipsoid e = RandomEllipsoid(rng);
    for (const Camera& cam : rig.cameras) {
      const auto ellipse = ProjectEllipsoid(ProjectionMatrix(cam), cam.CenterInWorld(), e);
      if (!ellipse) continue;
      const std::vector<Vector3d> rim = EllipsoidRim(e, cam.CenterInWorld(), 64);
      ASSERT_EQ(rim.size(), 64u);
      for (const Vector2d& px : OpenCvIdealPixels(cam, rim)) {
        worst = std::max(worst, ellipse->Distance(px));
        ++checked;
      }
    }
  }
  EXPECT_GT(checked, 200 * 64 * 3);  // nearly every ellipsoid is in front of nearly every camera
  std::printf("worst rim distance from the analytic conic: %.2g px over %d points\n", worst, checked);
  EXPECT_LT(worst, 0.05);
}

// The ellipse's own description agrees with the conic: its contour points
// satisfy x^T C x = 0, the normals point outwards, and a point moved 1 px
// along the normal is 1 px away.
TEST(EllipseProjection, ContourConicAndDistanceAgree) {
  const Rig rig = LoadRig(std::string(IRBENCH_SOURCE_DIR) + "/rigs/theater4.json");
  std::mt19937 rng(5);
  for (int trial = 0; trial < 50; ++trial) {
    const Ellipsoid e = RandomEllipsoid(rng);
    const Camera& cam = rig.cameras[trial % rig.cameras.size()];
    const auto ellipse = ProjectEllipsoid(ProjectionMatrix(cam), cam.CenterInWorld(), e);
    if (!ellipse) continue;
    std::vector<Vector2d> points, normals;
    ellipse->Contour(32, &points, &normals);
    const Eigen::Matrix3d conic = ellipse->Conic();
    for (size_t i = 0; i < points.size(); ++i) {
      const Eigen::Vector3d x(points[i].x(), points[i].y(), 1.0);
      EXPECT_NEAR(x.dot(conic * x), 0.0, 1e-9);
      EXPECT_LT(ellipse->Distance(points[i]), 1e-9);
      EXPECT_GT((points[i] - ellipse->center).dot(normals[i]), 0.0);
      EXPECT_NEAR(ellipse->Distance(points[i] + normals[i]), 1.0, 0.05 + 1.0 / ellipse->semi_axes[1]);
    }
    const Eigen::Vector3d c(ellipse->center.x(), ellipse->center.y(), 1.0);
    EXPECT_LT(c.dot(conic * c), 0.0);  // negative inside
  }
}

// A sphere seen along the optical axis projects to a circle of radius
// f * r / sqrt(d^2 - r^2) (analytic), centred on the principal point.
TEST(EllipseProjection, SphereOnTheAxisIsTheAnalyticCircle) {
  Camera cam;
  cam.fx = cam.fy = 300;
  cam.cx = 160;
  cam.cy = 120;
  const double d = 3.0, r = 0.4;
  Ellipsoid sphere;
  sphere.center = Vector3d(0, 0, d);  // camera at the origin looking down +z
  sphere.radii = Vector3d::Constant(r);
  const auto ellipse = ProjectEllipsoid(ProjectionMatrix(cam), cam.CenterInWorld(), sphere);
  ASSERT_TRUE(ellipse);
  EXPECT_NEAR(ellipse->center.x(), 160, 1e-9);
  EXPECT_NEAR(ellipse->center.y(), 120, 1e-9);
  const double expected = 300 * r / std::sqrt(d * d - r * r);
  EXPECT_NEAR(ellipse->semi_axes[0], expected, 1e-9);
  EXPECT_NEAR(ellipse->semi_axes[1], expected, 1e-9);
  // Half a pyramid level: the circle halves about the shifted pixel grid.
  const ImageEllipse half = ellipse->Scaled(0.5);
  EXPECT_NEAR(half.center.x(), (160 + 0.5) * 0.5 - 0.5, 1e-12);
  EXPECT_NEAR(half.semi_axes[0], expected / 2, 1e-9);
}

TEST(EllipseProjection, RefusesEllipsoidsBehindOrAroundTheCamera) {
  Camera cam;
  cam.fx = cam.fy = 300;
  Ellipsoid e;
  e.radii = Vector3d::Constant(0.3);
  e.center = Vector3d(0, 0, -2);  // behind
  EXPECT_FALSE(ProjectEllipsoid(ProjectionMatrix(cam), cam.CenterInWorld(), e));
  e.center = Vector3d(0, 0, 0.1);  // around the camera
  EXPECT_FALSE(ProjectEllipsoid(ProjectionMatrix(cam), cam.CenterInWorld(), e));
  e.center = Vector3d(0, 0.5, 0.1);  // straddling the camera's plane
  EXPECT_FALSE(ProjectEllipsoid(ProjectionMatrix(cam), cam.CenterInWorld(), e));
  EXPECT_TRUE(EllipsoidRim(e, e.center, 8).empty());
}

}  // namespace
}  // namespace irbench
