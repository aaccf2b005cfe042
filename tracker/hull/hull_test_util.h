#pragma once
// Test scenes for the hull tests: rings of cameras around the stage and exact
// silhouettes of analytic solids (a pixel is silhouette when the ray through
// its centre hits the solid).

#include <Eigen/Core>
#include <cmath>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "geometry/camera.h"

namespace irbench::testing {

// The sphere the hull tests carve from its silhouettes.
inline const Eigen::Vector3d kSphereCentre(0.2, -0.1, 1.0);
inline constexpr double kSphereRadius = 0.3;

// `ring` cameras on a circle of radius `radius_m` at height `height_m` and
// `high` more on a smaller circle above, all looking at `target`; 320 x 240,
// mild barrel distortion so the tests exercise the lens model.
inline std::vector<Camera> HullRig(int ring,
                                   int high,
                                   double radius_m = 3.5,
                                   double height_m = 1.2,
                                   const Eigen::Vector3d& target = {0, 0, 1.0}) {
  std::vector<Camera> cams;
  auto add = [&](const Eigen::Vector3d& position) {
    Camera cam;
    cam.name = "cam" + std::to_string(cams.size());
    cam.fx = 260;
    cam.fy = 260.5;
    cam.cx = 160.3;
    cam.cy = 119.6;
    cam.dist = {-0.1, 0.03, 0.0004, -0.0003, 0.0};
    cam.cam_from_world = *LookAt(position, target, Eigen::Vector3d::UnitZ());
    cams.push_back(cam);
  };
  for (int i = 0; i < ring; ++i) {
    const double a = 2 * M_PI * i / ring + 0.3;
    add({radius_m * std::cos(a), radius_m * std::sin(a), height_m});
  }
  for (int i = 0; i < high; ++i) {
    const double a = 2 * M_PI * i / high + 1.1;
    add({0.5 * radius_m * std::cos(a), 0.5 * radius_m * std::sin(a), 3.8});
  }
  return cams;
}

// Does the ray C + s d (s > 0) hit the sphere?
inline bool RayHitsSphere(const Eigen::Vector3d& c,
                          const Eigen::Vector3d& d,
                          const Eigen::Vector3d& centre,
                          double r) {
  const double s = (centre - c).dot(d);
  return s > 0 && (c + s * d - centre).squaredNorm() < r * r;
}

inline bool RayHitsBox(const Eigen::Vector3d& c,
                       const Eigen::Vector3d& d,
                       const Eigen::Vector3d& lo,
                       const Eigen::Vector3d& hi) {
  double s0 = 0, s1 = 1e9;
  for (int k = 0; k < 3; ++k) {
    if (std::abs(d[k]) < 1e-12) {
      if (c[k] < lo[k] || c[k] > hi[k]) return false;
      continue;
    }
    double t0 = (lo[k] - c[k]) / d[k], t1 = (hi[k] - c[k]) / d[k];
    if (t0 > t1) std::swap(t0, t1);
    s0 = std::max(s0, t0);
    s1 = std::min(s1, t1);
  }
  return s1 > s0;
}

template <typename Hit>
cv::Mat Rasterise(const Camera& cam, Hit hit) {
  cv::Mat mask = cv::Mat::zeros(cam.height, cam.width, CV_8UC1);
  const Eigen::Vector3d c = cam.CenterInWorld();
  for (int v = 0; v < cam.height; ++v) {
    for (int u = 0; u < cam.width; ++u) {
      const auto d = cam.PixelRayInWorld(Eigen::Vector2d(u, v));
      if (d && hit(c, *d)) mask.at<uint8_t>(v, u) = 255;
    }
  }
  return mask;
}

inline cv::Mat SphereSilhouette(const Camera& cam, const Eigen::Vector3d& centre, double r) {
  return Rasterise(cam, [&](const Eigen::Vector3d& c, const Eigen::Vector3d& d) {
    return RayHitsSphere(c, d, centre, r);
  });
}

inline cv::Mat BoxSilhouette(const Camera& cam,
                             const Eigen::Vector3d& lo,
                             const Eigen::Vector3d& hi) {
  return Rasterise(cam, [&](const Eigen::Vector3d& c, const Eigen::Vector3d& d) {
    return RayHitsBox(c, d, lo, hi);
  });
}

}  // namespace irbench::testing
