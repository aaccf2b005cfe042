#pragma once
// A calibrated camera: OpenCV's pinhole model with Brown–Conrady distortion
// (k1 k2 p1 p2 k3), so cv::projectPoints with the written calibration gives the
// same pixels. Pixel coordinates follow OpenCV: the centre of the top-left
// pixel is (0, 0), u to the right, v down.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <optional>
#include <string>

namespace irbench {

struct Camera {
  std::string name;
  int width = 320;
  int height = 240;
  double fx = 0, fy = 0, cx = 0, cy = 0;  // pixels
  std::array<double, 5> dist{};           // k1 k2 p1 p2 k3
  // OpenCV camera frame: x right, y down, z forward (the optical axis).
  Eigen::Isometry3d cam_from_world = Eigen::Isometry3d::Identity();

  Eigen::Matrix3d K() const;
  Eigen::Vector3d CenterInWorld() const { return cam_from_world.inverse().translation(); }

  // Pixel -> (distorted) normalised image coordinates ((u - cx) / fx, (v - cy) / fy),
  // and back. Normalised coordinates are x/z, y/z in the camera frame after
  // distortion; Undistort takes them to the ideal pinhole's.
  Eigen::Vector2d PixelToNormalised(const Eigen::Vector2d& px) const {
    return {(px.x() - cx) / fx, (px.y() - cy) / fy};
  }
  Eigen::Vector2d NormalisedToPixel(const Eigen::Vector2d& x) const {
    return {fx * x.x() + cx, fy * x.y() + cy};
  }
  // The undistorted normalised coordinates (a ray's x/z, y/z) seen at pixel
  // `px`: Undistort(PixelToNormalised(px)); nullopt where Undistort fails.
  std::optional<Eigen::Vector2d> UndistortPixel(const Eigen::Vector2d& px) const {
    return Undistort(PixelToNormalised(px));
  }

  // Applies the distortion to normalised image coordinates (x/z, y/z).
  Eigen::Vector2d Distort(const Eigen::Vector2d& x_undistorted) const;
  // Inverts Distort by Newton's method; nullopt when it does not converge.
  std::optional<Eigen::Vector2d> Undistort(const Eigen::Vector2d& x_distorted) const;

  // Ideal (undistorted) normalised coordinates -> pixel, with the distortion.
  Eigen::Vector2d DistortToPixel(const Eigen::Vector2d& x_undistorted) const {
    return NormalisedToPixel(Distort(x_undistorted));
  }

  // Projects a world point to pixels, exactly as cv::projectPoints (including its
  // treatment of points at z = 0). Check z > 0 yourself for visibility.
  Eigen::Vector2d Project(const Eigen::Vector3d& p_in_world) const;
  // The same for a point already in camera coordinates (cam_from_world * p):
  // Project(p) == ProjectInCamera(cam_from_world * p), bit for bit.
  Eigen::Vector2d ProjectInCamera(const Eigen::Vector3d& p_in_cam) const;
  // The unit ray direction in world coordinates through pixel `px`.
  std::optional<Eigen::Vector3d> PixelRayInWorld(const Eigen::Vector2d& px) const;

  // The same camera at `scale` times the resolution (intrinsics scaled about
  // pixel centres, so the field of view is unchanged).
  Camera Scaled(double scale) const;
};

// cam_from_world for a camera at `position` looking at `look_at` with `up`
// projecting upwards in the image. Returns nullopt when the view direction is
// zero or parallel to `up`.
std::optional<Eigen::Isometry3d> LookAt(const Eigen::Vector3d& position,
                                        const Eigen::Vector3d& look_at,
                                        const Eigen::Vector3d& up);

}  // namespace irbench
