// 3D axis points (thesis 4.4.2) of a capsule seen by calibrated cameras; the
// silhouettes are ray-traced against the capsule, so the true axis is exact.

#include "common/error.h"
#include "tracker/axis/axis3d.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

namespace irbench {
namespace {

double DistanceToSegment(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                         double* s_out = nullptr) {
  const double s = std::clamp((p - a).dot(b - a) / (b - a).squaredNorm(), 0.0, 1.0);
  if (s_out) *s_out = s;
  return (a + s * (b - a) - p).norm();
}

Camera MakeCamera(const std::string& name, const Eigen::Vector3d& position, const Eigen::Vector3d& target,
                  double k1) {
  Camera camera;
  camera.name = name;
  camera.fx = 300;
  camera.fy = 300;
  camera.cx = 159.5;
  camera.cy = 119.5;
  camera.dist = {k1, 0, 0, 0, 0};
  camera.cam_from_world = *LookAt(position, target, Eigen::Vector3d::UnitZ());
  return camera;
}

// Per pixel: does the viewing ray pass within `radius` of segment a-b?
cv::Mat1b RenderCapsule(const Camera& camera, const Eigen::Vector3d& a, const Eigen::Vector3d& b, double radius) {
  cv::Mat1b image(camera.height, camera.width, uchar(0));
  const Eigen::Vector3d c = camera.CenterInWorld();
  for (int v = 0; v < camera.height; ++v) {
    for (int u = 0; u < camera.width; ++u) {
      const auto ray = camera.PixelRayInWorld({double(u), double(v)});
      if (!ray) continue;
      // Distance from the line c + t ray to a + s (b - a), minimised over s in [0, 1].
      auto line_distance = [&](double s) {
        const Eigen::Vector3d x = a + s * (b - a) - c;
        return (x - x.dot(*ray) * *ray).norm();
      };
      const Eigen::Vector3d e = b - a, w = a - c;
      const Eigen::Vector3d e_perp = e - e.dot(*ray) * *ray, w_perp = w - w.dot(*ray) * *ray;
      const double s = e_perp.squaredNorm() > 1e-15 ? std::clamp(-w_perp.dot(e_perp) / e_perp.squaredNorm(), 0.0, 1.0)
                                                     : 0.0;
      if (line_distance(s) <= radius) image(v, u) = 255;
    }
  }
  return image;
}

std::vector<AxisView> CapsuleViews(const std::vector<Camera>& cameras, const Eigen::Vector3d& a,
                                   const Eigen::Vector3d& b, double radius) {
  std::vector<AxisView> views;
  for (const Camera& camera : cameras) {
    AxisView view;
    view.camera = camera;
    view.silhouette = RenderCapsule(camera, a, b, radius);
    view.graph = ExtractAxisPoints(view.silhouette);
    // The whole silhouette is one limb: every kept point is arm.
    for (const AxisPoint2d& p : view.graph.points) {
      view.labels.push_back(p.kept ? BodyPart::kLeftImageArm : BodyPart::kNone);
    }
    views.push_back(std::move(view));
  }
  return views;
}

TEST(Axis3dTest, CapsuleAxisFromFourCameras) {
  const Eigen::Vector3d a(-0.15, -0.05, 1.2), b(0.4, 0.2, 1.55);
  const double radius = 0.04;
  const Eigen::Vector3d target(0.1, 0.05, 1.35);
  const std::vector<Camera> cameras = {
      MakeCamera("north", {0.3, 3.0, 1.6}, target, -0.1), MakeCamera("east", {3.0, -0.4, 2.0}, target, 0.0),
      MakeCamera("south", {-0.5, -2.8, 1.0}, target, 0.05), MakeCamera("west", {-2.7, 0.8, 2.4}, target, 0.0)};
  const std::vector<AxisPoint3d> points = ReconstructAxis3d(CapsuleViews(cameras, a, b, radius));
  ASSERT_GT(points.size(), 30u);
  std::vector<double> distances, diameters;
  double s_min = 1, s_max = 0;
  for (const AxisPoint3d& p : points) {
    EXPECT_EQ(p.part, BodyPart::kArm);
    EXPECT_GE(p.support, 3);
    double s = 0;
    distances.push_back(DistanceToSegment(p.p_in_world, a, b, &s));
    diameters.push_back(p.diameter_m);
    if (s > 0.1 && s < 0.9) {
      s_min = std::min(s_min, s);
      s_max = std::max(s_max, s);
    }
  }
  std::sort(distances.begin(), distances.end());
  std::sort(diameters.begin(), diameters.end());
  // Mid-limb points are within millimetres; near the rounded ends the outlines
  // of different views are different 3D curves, so the worst reach about 1.5
  // radii (measured: median 5.9 mm, p90 26 mm, max 58 mm).
  EXPECT_LT(distances[distances.size() / 2], 0.01);
  EXPECT_LT(distances[distances.size() * 9 / 10], 0.03);
  EXPECT_LT(distances.back(), 1.6 * radius);
  EXPECT_NEAR(diameters[diameters.size() / 2], 2 * radius, 0.012);
  // The points cover the axis, not one spot.
  EXPECT_LT(s_min, 0.2);
  EXPECT_GT(s_max, 0.8);
}

TEST(Axis3dTest, CameraPairCoplanarWithTheLimbGivesNoPoints) {
  // Both camera centres and the limb lie in the plane z = 1.3: each epipolar
  // line runs along the other image's axis (thesis 4.4.2's special case).
  const Eigen::Vector3d a(-0.3, 0.0, 1.3), b(0.3, 0.0, 1.3);
  const std::vector<Camera> cameras = {MakeCamera("front", {0.5, 3.0, 1.3}, {0, 0, 1.3}, 0.0),
                                       MakeCamera("back", {-0.8, -3.0, 1.3}, {0, 0, 1.3}, 0.0)};
  const std::vector<AxisView> views = CapsuleViews(cameras, a, b, 0.04);
  const std::vector<AxisPoint3d> guarded = ReconstructAxis3d(views);
  Axis3dOptions no_skip;
  no_skip.min_epipolar_angle_deg = 0;
  const std::vector<AxisPoint3d> unguarded = ReconstructAxis3d(views, no_skip);
  // Without the guard the degenerate pair gives many points; with it, only a
  // few from the rounded ends survive (their local 2D axis bends).
  EXPECT_GT(unguarded.size(), 40u);
  EXPECT_LE(guarded.size() * 10, unguarded.size());
  // Raise one camera out of the plane and the pair triangulates again.
  const std::vector<Camera> raised = {cameras[0], MakeCamera("back", {-0.8, -2.0, 3.2}, {0, 0, 1.3}, 0.0)};
  const std::vector<AxisPoint3d> points = ReconstructAxis3d(CapsuleViews(raised, a, b, 0.04));
  ASSERT_GT(points.size(), 20u);
  std::vector<double> distances;
  for (const AxisPoint3d& p : points) distances.push_back(DistanceToSegment(p.p_in_world, a, b));
  std::sort(distances.begin(), distances.end());
  EXPECT_LT(distances[distances.size() / 2], 0.01);
  EXPECT_LT(distances.back(), 1.6 * 0.04);
}

TEST(Axis3dTest, OptionsRejectBadValues) {
  Axis3dOptions options;
  EXPECT_NO_THROW(options.Check());
  options.min_epipolar_angle_deg = 95;
  EXPECT_THROW(options.Check(), InputError);
  BodyAxesOptions all;
  all.max_view_elevation_deg = -1;
  EXPECT_THROW(all.Check(), InputError);
  EXPECT_THROW(ReconstructBodyAxes({Camera{}}, {}), std::invalid_argument);
}

}  // namespace
}  // namespace irbench
