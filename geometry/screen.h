#pragma once
// Projection screens with a 2D screen coordinate frame (metres along the
// surface) and named targets, as a real installation would survey them.
//
// Cylinder: the part of a vertical cylinder (centre, radius) between two angles
// about +z (degrees from +x, counter-clockwise) and two heights. Screen x (s)
// is arc length from the edge on the viewer's left (angle_left_deg) towards the
// right; screen y (t) is height above the bottom edge z0.
// Plane: a rectangle with `origin` at the lower-left corner as seen from the
// front, unit `right` and `up` axes; its front faces right x up.
//
// Geometry only: how the sim renders a screen (its material, its mesh) is in
// sim/scene/screen_mesh.h; calib/screens.json is read and written by
// sequence_format/screens.h.

#include <Eigen/Core>
#include <map>
#include <optional>
#include <string>

namespace irbench {

struct ScreenSurface {
  enum class Kind { kCylinder, kPlane };
  std::string name;
  Kind kind = Kind::kPlane;
  // Cylinder.
  Eigen::Vector2d center_xy = Eigen::Vector2d::Zero();
  double radius = 1.0;
  double angle_left_deg = 150.0;
  double angle_right_deg = 30.0;
  double z0 = 0.0, z1 = 1.0;
  // Plane.
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  Eigen::Vector3d right = Eigen::Vector3d::UnitX();
  Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
  double width = 1.0, height = 1.0;

  std::map<std::string, Eigen::Vector2d> targets;  // screen coordinates, metres

  // Extent of the screen coordinates: s in [0, Size().x()], t in [0, Size().y()].
  Eigen::Vector2d Size() const;
  // World point of screen coordinates (s, t).
  Eigen::Vector3d PointAt(const Eigen::Vector2d& st) const;
  // Where a ray (origin, direction) first hits the screen from the front, in
  // screen coordinates; nullopt when it misses.
  std::optional<Eigen::Vector2d> Intersect(const Eigen::Vector3d& ray_origin,
                                           const Eigen::Vector3d& ray_dir) const;
  // Nearest named target to screen coordinates (empty when there are none).
  std::string NearestTarget(const Eigen::Vector2d& st) const;
};

}  // namespace irbench
