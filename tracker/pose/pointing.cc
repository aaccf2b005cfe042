#include "tracker/pose/pointing.h"

#include <limits>

namespace irbench {

std::optional<PointingRay> Pointing(const Eigen::Vector3d& head, const Eigen::Vector3d& hand_tip,
                                    const std::vector<ScreenSurface>& screens) {
  const Eigen::Vector3d d = hand_tip - head;
  if (d.norm() < 1e-6) return std::nullopt;
  PointingRay ray;
  ray.origin = head;
  ray.dir = d.normalized();
  double nearest = std::numeric_limits<double>::infinity();
  for (const ScreenSurface& screen : screens) {
    const auto st = screen.Intersect(ray.origin, ray.dir);
    if (!st) continue;
    const double distance = (screen.PointAt(*st) - ray.origin).norm();
    if (distance >= nearest) continue;
    nearest = distance;
    ray.screen = screen.name;
    ray.screen_hit = *st;
    const std::string target = screen.NearestTarget(*st);
    ray.target = target.empty() ? std::nullopt : std::optional<std::string>(target);
  }
  return ray;
}

}  // namespace irbench
