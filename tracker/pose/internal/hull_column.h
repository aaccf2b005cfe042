#pragma once
// Private to tracker/pose: a vertical column of the voxel hull, the voxels
// whose centres lie within a radius of a point across (HullHeadCentre's head,
// HullColumnTop's tiptoe).

#include <Eigen/Core>
#include <algorithm>
#include <cmath>

#include "tracker/hull/voxel_hull.h"

namespace irbench::pose_internal {

struct HullColumn {
  // The column about `xy` (world metres) with `radius_m`; the voxel index
  // box [x0, x1) x [y0, y1) that holds it, clamped to the grid.
  HullColumn(const VoxelHull& hull, const Eigen::Vector2d& xy, double radius_m)
      : hull(hull), xy(xy), radius_m(radius_m) {
    const Eigen::Vector2d lo = (xy - Eigen::Vector2d::Constant(radius_m) - hull.origin_m.head<2>()) / hull.voxel_size_m;
    const Eigen::Vector2d hi = (xy + Eigen::Vector2d::Constant(radius_m) - hull.origin_m.head<2>()) / hull.voxel_size_m;
    x0 = std::max(0, static_cast<int>(std::floor(lo.x())));
    y0 = std::max(0, static_cast<int>(std::floor(lo.y())));
    x1 = std::min(hull.nx, static_cast<int>(std::ceil(hi.x())));
    y1 = std::min(hull.ny, static_cast<int>(std::ceil(hi.y())));
  }
  // Voxel (x, y, z) is occupied and in the column.
  bool Holds(int x, int y, int z) const {
    return hull.Occupied(x, y, z) && (hull.VoxelCenter(x, y, z).head<2>() - xy).norm() <= radius_m;
  }
  // Layer z holds an occupied voxel of the column.
  bool LayerHolds(int z) const {
    for (int y = y0; y < y1; ++y) {
      for (int x = x0; x < x1; ++x) {
        if (Holds(x, y, z)) return true;
      }
    }
    return false;
  }

  const VoxelHull& hull;
  Eigen::Vector2d xy;
  double radius_m;
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
};

}  // namespace irbench::pose_internal
