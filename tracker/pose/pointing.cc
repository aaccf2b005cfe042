#include "tracker/pose/pointing.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "common/error.h"
#include "tracker/pose/internal/hull_column.h"

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

void HullHeadOptions::Check() const {
  if (!(radius_m > 0)) throw InputError("", "pose.hull_head.radius_m", "must be positive");
  if (!(slab > 0)) throw InputError("", "pose.hull_head.slab", "must be positive");
  if (!(below_top >= 0)) throw InputError("", "pose.hull_head.below_top", "must be non-negative");
  if (!(back_m >= 0)) throw InputError("", "pose.hull_head.back_m", "must be non-negative");
  if (!(max_gap_m > 0)) throw InputError("", "pose.hull_head.max_gap_m", "must be positive");
}

std::optional<Eigen::Vector3d> HullHeadCentre(const VoxelHull& hull, const Eigen::Vector3d& model_head,
                                              const Eigen::Vector3d& forward, double height_m,
                                              const HullHeadOptions& options) {
  if (hull.voxel_size_m <= 0 || hull.occupied.empty()) return std::nullopt;
  const double crown = model_head.z() + options.below_top * height_m;
  // The voxels that may hold the head: within radius_m of its centre across,
  // and from well below the crown to max_gap_m above it.
  const pose_internal::HullColumn column(hull, model_head.head<2>(), options.radius_m);
  const int z0 = std::max(
      0, static_cast<int>(std::floor(
             (crown - options.max_gap_m - options.slab * height_m - hull.origin_m.z()) / hull.voxel_size_m)));
  const int z1 = std::min(
      hull.nz,
      static_cast<int>(std::ceil((crown + options.max_gap_m + hull.voxel_size_m - hull.origin_m.z()) / hull.voxel_size_m)));
  // The top: the highest layer with a head voxel.
  int top = -1;
  for (int z = z1 - 1; z >= z0 && top < 0; --z) {
    if (column.LayerHolds(z)) top = z;
  }
  if (top < 0) return std::nullopt;
  const double top_m = hull.origin_m.z() + (top + 1) * hull.voxel_size_m;  // the top layer's upper face
  if (std::abs(top_m - crown) > options.max_gap_m) return std::nullopt;
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  int count = 0;
  for (int z = top; z >= z0 && hull.VoxelCenter(0, 0, z).z() >= top_m - options.slab * height_m; --z) {
    for (int y = column.y0; y < column.y1; ++y) {
      for (int x = column.x0; x < column.x1; ++x) {
        if (!column.Holds(x, y, z)) continue;
        sum += hull.VoxelCenter(x, y, z).head<2>();
        ++count;
      }
    }
  }
  Eigen::Vector3d head(0, 0, top_m - options.below_top * height_m);
  head.head<2>() = sum / count;
  const Eigen::Vector2d facing = forward.head<2>();
  if (facing.norm() > 1e-9) head.head<2>() -= options.back_m * facing.normalized();
  return head;
}

}  // namespace irbench
