#include "tracker/body_model/ellipse_projection.h"

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <cmath>

namespace irbench {

using Eigen::Matrix3d;
using Eigen::Vector2d;
using Eigen::Vector3d;

Matrix3d ImageEllipse::Conic() const {
  Matrix3d c;
  c.topLeftCorner<2, 2>() = shape;
  c.topRightCorner<2, 1>() = -shape * center;
  c.bottomLeftCorner<1, 2>() = (-shape * center).transpose();
  c(2, 2) = center.dot(shape * center) - 1.0;
  return c;
}

void ImageEllipse::Contour(int count, std::vector<Vector2d>* points, std::vector<Vector2d>* normals) const {
  points->clear();
  if (normals) normals->clear();
  const Vector2d major(std::cos(angle_rad), std::sin(angle_rad));
  const Vector2d minor(-major.y(), major.x());
  for (int i = 0; i < count; ++i) {
    const double t = 2 * M_PI * i / count;
    const Vector2d p = center + semi_axes[0] * std::cos(t) * major + semi_axes[1] * std::sin(t) * minor;
    points->push_back(p);
    if (normals) normals->push_back((shape * (p - center)).normalized());
  }
}

double ImageEllipse::Distance(const Vector2d& p) const {
  const Vector2d d = p - center;
  const double g = d.dot(shape * d) - 1.0;
  const double grad = 2.0 * (shape * d).norm();
  return grad > 0 ? std::abs(g) / grad : semi_axes[1];
}

ImageEllipse ImageEllipse::Scaled(double scale) const {
  ImageEllipse e = *this;
  e.center = (center.array() + 0.5) * scale - 0.5;
  e.shape = shape / (scale * scale);
  e.semi_axes = semi_axes * scale;
  return e;
}

Eigen::Matrix<double, 3, 4> ProjectionMatrix(const Camera& camera) {
  Eigen::Matrix<double, 3, 4> rt;
  rt.leftCols<3>() = camera.cam_from_world.linear();
  rt.col(3) = camera.cam_from_world.translation();
  return camera.K() * rt;
}

std::optional<ImageEllipse> ProjectEllipsoid(const Eigen::Matrix<double, 3, 4>& P, const Vector3d& camera_center_world,
                                             const Ellipsoid& ellipsoid) {
  const Matrix3d& R = ellipsoid.world_from_segment;
  const Vector3d& r = ellipsoid.radii;
  // The camera must be outside, the whole ellipsoid in front of it.
  const Vector3d e_local = (R.transpose() * (camera_center_world - ellipsoid.center)).cwiseQuotient(r);
  if (e_local.squaredNorm() <= 1.0 + 1e-9) return std::nullopt;
  // Depth along the optical axis (row 3 of K[R|t] is the camera frame's z row).
  const Vector3d axis = P.block<1, 3>(2, 0).transpose();
  const double depth_center = axis.dot(ellipsoid.center) + P(2, 3);
  const double depth_extent = (r.asDiagonal() * (R.transpose() * axis)).norm();
  if (depth_center - depth_extent <= 1e-6 * axis.norm()) return std::nullopt;

  // Dual quadric of X = c + R diag(r) u, |u| = 1: H diag(1,1,1,-1) H^T.
  Eigen::Matrix4d dual;
  const Matrix3d RD = R * r.asDiagonal();
  dual.topLeftCorner<3, 3>() = RD * RD.transpose() - ellipsoid.center * ellipsoid.center.transpose();
  dual.topRightCorner<3, 1>() = -ellipsoid.center;
  dual.bottomLeftCorner<1, 3>() = -ellipsoid.center.transpose();
  dual(3, 3) = -1.0;
  const Matrix3d dual_conic = P * dual * P.transpose();
  // adj(C*) is the conic up to scale; the scale and sign drop out below.
  Eigen::FullPivLU<Matrix3d> lu(dual_conic);
  if (!lu.isInvertible()) return std::nullopt;
  const Matrix3d conic = lu.inverse();
  const Eigen::Matrix2d c2 = conic.topLeftCorner<2, 2>();
  const Vector2d l = conic.topRightCorner<2, 1>();
  if (std::abs(c2.determinant()) < 1e-300) return std::nullopt;
  ImageEllipse out;
  out.center = -c2.inverse() * l;
  const double k = conic(2, 2) + l.dot(out.center);
  if (k == 0.0) return std::nullopt;
  out.shape = c2 / (-k);
  out.shape = 0.5 * (out.shape + out.shape.transpose()).eval();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(out.shape);
  const Vector2d lambda = eig.eigenvalues();  // ascending: the major axis first
  if (!(lambda[0] > 0)) return std::nullopt;
  out.semi_axes = Vector2d(1.0 / std::sqrt(lambda[0]), 1.0 / std::sqrt(lambda[1]));
  const Vector2d major = eig.eigenvectors().col(0);
  out.angle_rad = std::atan2(major.y(), major.x());
  return out;
}

std::vector<Vector3d> EllipsoidRim(const Ellipsoid& ellipsoid, const Vector3d& camera_center_world, int count) {
  const Matrix3d& R = ellipsoid.world_from_segment;
  const Vector3d& r = ellipsoid.radii;
  const Vector3d e = (R.transpose() * (camera_center_world - ellipsoid.center)).cwiseQuotient(r);
  const double n2 = e.squaredNorm();
  std::vector<Vector3d> out;
  if (n2 <= 1.0) return out;
  // On the unit sphere the rim seen from e is the circle u.e = 1; the affine
  // map to the ellipsoid keeps tangency.
  const Vector3d m = e / n2;
  const double rho = std::sqrt(1.0 - 1.0 / n2);
  const Vector3d n = e.normalized();
  const Vector3d b1 = n.unitOrthogonal();
  const Vector3d b2 = n.cross(b1);
  for (int i = 0; i < count; ++i) {
    const double t = 2 * M_PI * i / count;
    const Vector3d u = m + rho * (std::cos(t) * b1 + std::sin(t) * b2);
    out.push_back(ellipsoid.center + R * r.cwiseProduct(u));
  }
  return out;
}

std::vector<ImageEllipse> ProjectBody(const Camera& camera, const Eigen::Matrix<double, 3, 4>& P,
                                      const PosedBody& body) {
  std::vector<ImageEllipse> out;
  const Vector3d center = camera.CenterInWorld();
  for (const Ellipsoid& e : body.segments) {
    if (auto ellipse = ProjectEllipsoid(P, center, e)) out.push_back(*ellipse);
  }
  return out;
}

std::vector<std::vector<Eigen::Vector2d>> BodyOutlines(const Camera& camera, const PosedBody& body, int count) {
  const Eigen::Matrix3d K_inv = camera.K().inverse();
  std::vector<std::vector<Eigen::Vector2d>> out;
  for (const ImageEllipse& e : ProjectBody(camera, ProjectionMatrix(camera), body)) {
    std::vector<Eigen::Vector2d> ideal;
    e.Contour(count, &ideal, nullptr);
    std::vector<Eigen::Vector2d>& outline = out.emplace_back();
    for (const Eigen::Vector2d& p : ideal) {
      const Eigen::Vector3d n = K_inv * p.homogeneous();
      const Eigen::Vector2d d = camera.Distort(n.head<2>() / n.z());
      outline.emplace_back(camera.fx * d.x() + camera.cx, camera.fy * d.y() + camera.cy);
    }
  }
  return out;
}

}  // namespace irbench
