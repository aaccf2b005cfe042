#include "geometry/screen.h"

#include <Eigen/Geometry>
#include <cmath>
#include <limits>

namespace irbench {
namespace {
constexpr double kDegToRad = M_PI / 180.0;
}

Eigen::Vector2d ScreenSurface::Size() const {
  if (kind == Kind::kCylinder) {
    return {radius * (angle_left_deg - angle_right_deg) * kDegToRad, z1 - z0};
  }
  return {width, height};
}

Eigen::Vector3d ScreenSurface::PointAt(const Eigen::Vector2d& st) const {
  if (kind == Kind::kCylinder) {
    const double angle = angle_left_deg * kDegToRad - st.x() / radius;
    return {center_xy.x() + radius * std::cos(angle), center_xy.y() + radius * std::sin(angle),
            z0 + st.y()};
  }
  return origin + right * st.x() + up * st.y();
}

std::optional<Eigen::Vector2d> ScreenSurface::Intersect(const Eigen::Vector3d& ray_origin,
                                                        const Eigen::Vector3d& ray_dir) const {
  if (kind == Kind::kCylinder) {
    const Eigen::Vector2d o = ray_origin.head<2>() - center_xy;
    const Eigen::Vector2d d = ray_dir.head<2>();
    const double a = d.squaredNorm();
    if (a < 1e-12) return std::nullopt;
    const double b = 2 * o.dot(d);
    const double c = o.squaredNorm() - radius * radius;
    const double disc = b * b - 4 * a * c;
    if (disc < 0) return std::nullopt;
    const double sq = std::sqrt(disc);
    // From inside (c < 0) the front hit is the far root; from outside, the
    // inner face is the far root as well.
    for (double lambda : {(-b + sq) / (2 * a), (-b - sq) / (2 * a)}) {
      if (lambda <= 0) continue;
      const Eigen::Vector3d p = ray_origin + lambda * ray_dir;
      double angle = std::atan2(p.y() - center_xy.y(), p.x() - center_xy.x()) / kDegToRad;
      // Bring the angle into the screen's range modulo 360.
      while (angle < angle_right_deg - 180) angle += 360;
      while (angle > angle_right_deg + 180) angle -= 360;
      const Eigen::Vector2d st(radius * (angle_left_deg - angle) * kDegToRad, p.z() - z0);
      const Eigen::Vector2d size = Size();
      if (st.x() >= 0 && st.x() <= size.x() && st.y() >= 0 && st.y() <= size.y()) return st;
      return std::nullopt;
    }
    return std::nullopt;
  }
  const Eigen::Vector3d normal = right.cross(up);
  const double denom = ray_dir.dot(normal);
  if (denom >= -1e-12) return std::nullopt;  // parallel or hitting the back
  const double lambda = (origin - ray_origin).dot(normal) / denom;
  if (lambda <= 0) return std::nullopt;
  const Eigen::Vector3d p = ray_origin + lambda * ray_dir;
  const Eigen::Vector2d st((p - origin).dot(right), (p - origin).dot(up));
  if (st.x() < 0 || st.x() > width || st.y() < 0 || st.y() > height) return std::nullopt;
  return st;
}

std::string ScreenSurface::NearestTarget(const Eigen::Vector2d& st) const {
  std::string best;
  double best_d = std::numeric_limits<double>::infinity();
  for (const auto& [name, target] : targets) {
    const double d = (target - st).norm();
    if (d < best_d) {
      best_d = d;
      best = name;
    }
  }
  return best;
}

}  // namespace irbench
