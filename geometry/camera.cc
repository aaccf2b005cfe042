#include "geometry/camera.h"

#include <cmath>

namespace irbench {

Eigen::Matrix3d Camera::K() const {
  Eigen::Matrix3d k;
  k << fx, 0, cx, 0, fy, cy, 0, 0, 1;
  return k;
}

Eigen::Vector2d Camera::Distort(const Eigen::Vector2d& x_u) const {
  const double k1 = dist[0], k2 = dist[1], p1 = dist[2], p2 = dist[3], k3 = dist[4];
  const double x = x_u.x(), y = x_u.y();
  const double r2 = x * x + y * y;
  const double radial = 1 + r2 * (k1 + r2 * (k2 + r2 * k3));
  return {x * radial + 2 * p1 * x * y + p2 * (r2 + 2 * x * x),
          y * radial + p1 * (r2 + 2 * y * y) + 2 * p2 * x * y};
}

std::optional<Eigen::Vector2d> Camera::Undistort(const Eigen::Vector2d& x_d) const {
  const double k1 = dist[0], k2 = dist[1], p1 = dist[2], p2 = dist[3], k3 = dist[4];
  Eigen::Vector2d x = x_d;
  for (int iter = 0; iter < 50; ++iter) {
    const Eigen::Vector2d residual = Distort(x) - x_d;
    if (residual.norm() < 1e-15) return x;
    // Analytic Jacobian of Distort.
    const double u = x.x(), v = x.y();
    const double r2 = u * u + v * v;
    const double radial = 1 + r2 * (k1 + r2 * (k2 + r2 * k3));
    const double dradial_dr2 = k1 + r2 * (2 * k2 + 3 * r2 * k3);
    Eigen::Matrix2d jac;
    jac(0, 0) = radial + u * dradial_dr2 * 2 * u + 2 * p1 * v + p2 * 6 * u;
    jac(0, 1) = u * dradial_dr2 * 2 * v + 2 * p1 * u + p2 * 2 * v;
    jac(1, 0) = v * dradial_dr2 * 2 * u + p1 * 2 * u + 2 * p2 * v;
    jac(1, 1) = radial + v * dradial_dr2 * 2 * v + p1 * 6 * v + 2 * p2 * u;
    if (std::abs(jac.determinant()) < 1e-12) return std::nullopt;
    x -= jac.inverse() * residual;
    if (!x.allFinite()) return std::nullopt;
  }
  if ((Distort(x) - x_d).norm() < 1e-12) return x;
  return std::nullopt;
}

Eigen::Vector2d Camera::Project(const Eigen::Vector3d& p_in_world) const {
  return ProjectInCamera(cam_from_world * p_in_world);
}

Eigen::Vector2d Camera::ProjectInCamera(const Eigen::Vector3d& p_in_cam) const {
  // cv::projectPoints: z = z ? 1/z : 1.
  const double inv_z = p_in_cam.z() != 0 ? 1.0 / p_in_cam.z() : 1.0;
  return DistortToPixel({p_in_cam.x() * inv_z, p_in_cam.y() * inv_z});
}

std::optional<Eigen::Vector3d> Camera::PixelRayInWorld(const Eigen::Vector2d& px) const {
  const auto x_u = UndistortPixel(px);
  if (!x_u) return std::nullopt;
  const Eigen::Vector3d dir_in_cam = Eigen::Vector3d(x_u->x(), x_u->y(), 1.0).normalized();
  return cam_from_world.linear().transpose() * dir_in_cam;
}

Camera Camera::Scaled(double scale) const {
  Camera out = *this;
  out.width = static_cast<int>(std::lround(width * scale));
  out.height = static_cast<int>(std::lround(height * scale));
  out.fx = fx * scale;
  out.fy = fy * scale;
  // Pixel centres: the continuous image edge -0.5 maps to -0.5.
  out.cx = (cx + 0.5) * scale - 0.5;
  out.cy = (cy + 0.5) * scale - 0.5;
  return out;
}

std::optional<Eigen::Isometry3d> LookAt(const Eigen::Vector3d& position,
                                        const Eigen::Vector3d& look_at,
                                        const Eigen::Vector3d& up) {
  const Eigen::Vector3d forward = look_at - position;
  if (forward.norm() < 1e-9 || up.norm() < 1e-9) return std::nullopt;
  const Eigen::Vector3d z_axis = forward.normalized();
  const Eigen::Vector3d right = z_axis.cross(up);
  if (right.norm() < 1e-6 * up.norm()) return std::nullopt;
  const Eigen::Vector3d x_axis = right.normalized();
  const Eigen::Vector3d y_axis = z_axis.cross(x_axis);  // points down in the image
  Eigen::Matrix3d cam_from_world_rot;
  cam_from_world_rot.row(0) = x_axis.transpose();
  cam_from_world_rot.row(1) = y_axis.transpose();
  cam_from_world_rot.row(2) = z_axis.transpose();
  Eigen::Isometry3d cam_from_world = Eigen::Isometry3d::Identity();
  cam_from_world.linear() = cam_from_world_rot;
  cam_from_world.translation() = -cam_from_world_rot * position;
  return cam_from_world;
}

}  // namespace irbench
