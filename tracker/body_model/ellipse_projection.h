#pragma once
// Analytic projection of an ellipsoid into a pinhole camera (thesis 6.2.3,
// Eq. 6.2-6.6): the outline of a projected ellipsoid is the conic where the
// viewing rays graze it. With the ellipsoid as the quadric X^T A X = 0 (Eq. 6.2,
// homogeneous), its dual A* = adj(A) projects to the image's dual conic
// C* = P A* P^T, and the outline is x^T C x = 0 with C = adj(C*) — the same
// conic as the thesis's back-projection-line derivation, without the pseudo
// inverse.
//
// Pixels are *ideal* (undistorted) pixels of the camera's K: the tracker
// undistorts its silhouettes once per frame (UndistortSilhouette) and then
// compares them with undistorted model outlines. Pixel centres are integers
// (OpenCV's convention).

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "geometry/camera.h"
#include "tracker/body_model/body_model.h"

namespace irbench {

// An image ellipse: points x with (x - center)^T M (x - center) <= 1.
struct ImageEllipse {
  Eigen::Vector2d center = Eigen::Vector2d::Zero();
  Eigen::Matrix2d shape = Eigen::Matrix2d::Identity();  // M, symmetric positive definite
  Eigen::Vector2d semi_axes = Eigen::Vector2d::Ones();  // pixels, major first
  double angle_rad = 0;                                 // major axis from +u towards +v

  // Eq. 6.6: the conic matrix (homogeneous pixels), scaled so that it is
  // negative inside: x^T C x < 0 inside, 0 on the outline.
  Eigen::Matrix3d Conic() const;
  // Points on the outline, `count` of them evenly spaced in the ellipse's
  // parameter, with outward unit normals (thesis 6.2.4's model points).
  void Contour(int count, std::vector<Eigen::Vector2d>* points, std::vector<Eigen::Vector2d>* normals) const;
  // First-order (Sampson) distance from `p` to the outline, pixels.
  double Distance(const Eigen::Vector2d& p) const;
  // The same ellipse in an image scaled by `scale` (a pyramid level: 0.5 halves
  // the resolution), pixel centres kept on integers.
  ImageEllipse Scaled(double scale) const;
};

// The 3x4 projection P = K [R | t] of the camera's ideal pinhole.
Eigen::Matrix<double, 3, 4> ProjectionMatrix(const Camera& camera);

// Projects `ellipsoid` (world metres) with `P`. nullopt when the outline is
// not an ellipse: the camera inside or level with the ellipsoid, or the
// ellipsoid partly behind the camera.
std::optional<ImageEllipse> ProjectEllipsoid(const Eigen::Matrix<double, 3, 4>& P,
                                             const Eigen::Vector3d& camera_center_world, const Ellipsoid& ellipsoid);

// Points on the ellipsoid's rim as seen from `camera_center_world` (the
// points whose tangent planes contain the centre), `count` of them: what
// projects onto the outline. Empty when the centre is inside.
std::vector<Eigen::Vector3d> EllipsoidRim(const Ellipsoid& ellipsoid, const Eigen::Vector3d& camera_center_world,
                                          int count);

// The model's segments projected into one camera with its P (ideal pixels);
// segments that do not project to an ellipse are left out.
std::vector<ImageEllipse> ProjectBody(const Camera& camera, const Eigen::Matrix<double, 3, 4>& P,
                                      const PosedBody& body);

// The posed body's segment outlines as the camera's real (distorted) image
// shows them: each segment's analytic outline, `count` points, taken from
// ideal pixels through the camera's lens distortion. What overlays and the
// report draw; segments with no elliptic outline are left out.
std::vector<std::vector<Eigen::Vector2d>> BodyOutlines(const Camera& camera, const PosedBody& body, int count);

}  // namespace irbench
