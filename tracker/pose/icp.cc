#include "tracker/pose/icp.h"

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>

#include "tracker/body_model/ellipse_projection.h"
#include "common/error.h"

namespace irbench {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;

struct Edge {
  Vector2d a, b, normal;  // outward unit normal
};

std::vector<Edge> OutlineEdges(const std::vector<std::vector<Vector2d>>& polygons) {
  std::vector<Edge> edges;
  for (const auto& poly : polygons) {
    const size_t n = poly.size();
    if (n < 3) continue;
    double area2 = 0;
    for (size_t i = 0; i < n; ++i) {
      const Vector2d& p = poly[i];
      const Vector2d& q = poly[(i + 1) % n];
      area2 += p.x() * q.y() - q.x() * p.y();
    }
    const double sign = area2 > 0 ? 1.0 : -1.0;
    for (size_t i = 0; i < n; ++i) {
      const Vector2d& a = poly[i];
      const Vector2d& b = poly[(i + 1) % n];
      const Vector2d d = b - a;
      if (d.norm() < 1e-9) continue;
      edges.push_back({a, b, sign * Vector2d(d.y(), -d.x()).normalized()});
    }
  }
  return edges;
}

// Closest point on an edge whose normal agrees with `normal`; nullopt if none.
std::optional<Vector2d> ClosestOutlinePoint(const std::vector<Edge>& edges, const Vector2d& q, const Vector2d& normal,
                                            double min_cos) {
  double best = std::numeric_limits<double>::infinity();
  std::optional<Vector2d> out;
  for (const Edge& e : edges) {
    if (e.normal.dot(normal) <= min_cos) continue;
    const Vector2d ab = e.b - e.a;
    const double t = std::clamp((q - e.a).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
    const Vector2d p = e.a + t * ab;
    const double d = (p - q).squaredNorm();
    if (d < best) {
      best = d;
      out = p;
    }
  }
  return out;
}

struct Pair {
  Vector2d model, data;
  double weight;
};

// The weighted model/outline pairs of `segment` in one view.
std::vector<Pair> SegmentPairs(const std::vector<std::optional<ImageEllipse>>& ellipses, int segment,
                               const std::vector<Edge>& edges, const IcpOptions& options) {
  std::vector<Pair> pairs;
  if (!ellipses[segment]) return pairs;
  std::vector<Vector2d> points, normals;
  ellipses[segment]->Contour(options.points_per_segment, &points, &normals);
  const double min_cos = std::cos(options.max_normal_angle_rad);
  for (size_t i = 0; i < points.size(); ++i) {
    bool hidden = false;
    for (int other = 0; other < kSegmentCount && !hidden; ++other) {
      if (other == segment || !ellipses[other]) continue;
      const Vector2d d = points[i] - ellipses[other]->center;
      hidden = d.dot(ellipses[other]->shape * d) < 1.0;
    }
    if (hidden) continue;
    const auto p = ClosestOutlinePoint(edges, points[i], normals[i], min_cos);
    if (!p) continue;
    const double dist = (*p - points[i]).norm();
    if (dist > options.max_distance_px) continue;
    pairs.push_back({points[i], *p, std::exp(-dist / options.weight_scale_px)});
  }
  return pairs;
}

std::vector<std::optional<ImageEllipse>> ProjectSegments(const IcpView& view, const PosedBody& body) {
  std::vector<std::optional<ImageEllipse>> out;
  const Vector3d center = view.camera.CenterInWorld();
  for (const Ellipsoid& e : body.segments) out.push_back(ProjectEllipsoid(view.projection, center, e));
  return out;
}

// A 3D rotation vector from per-camera rotations `angle` about viewing rays
// `axis` (unit), combined by weighted least squares; the component along the
// limb (`limb_dir`), which no silhouette shows, is removed.
Vector3d CombineRotations(const std::vector<Vector3d>& axes, const std::vector<double>& angles,
                          const std::vector<double>& weights, const Vector3d& limb_dir, bool least_squares) {
  if (!least_squares) {
    std::vector<Eigen::Quaterniond> q;
    for (size_t i = 0; i < axes.size(); ++i) q.emplace_back(Eigen::AngleAxisd(angles[i], axes[i]));
    const Eigen::AngleAxisd mean(AverageQuaternions(q));
    return mean.angle() * mean.axis();
  }
  Eigen::Matrix3d A = 1e-3 * Eigen::Matrix3d::Identity();
  Vector3d b = Vector3d::Zero();
  for (size_t i = 0; i < axes.size(); ++i) {
    A += weights[i] * axes[i] * axes[i].transpose();
    b += weights[i] * angles[i] * axes[i];
  }
  Vector3d omega = A.lu().solve(b);
  omega -= omega.dot(limb_dir) * limb_dir;
  return omega;
}

}  // namespace

void IcpOptions::Check() const {
  if (iterations < 0) throw InputError("", "icp.iterations", "must be 0 or more");
  if (points_per_segment < 4) throw InputError("", "icp.points_per_segment", "must be at least 4");
  if (!(weight_scale_px > 0)) throw InputError("", "icp.weight_scale_px", "must be positive");
  if (!(max_distance_px > 0)) throw InputError("", "icp.max_distance_px", "must be positive");
  if (!(max_normal_angle_rad > 0 && max_normal_angle_rad <= M_PI)) {
    throw InputError("", "icp.max_normal_angle_rad", "must be in (0, pi]");
  }
}

Eigen::Quaterniond AverageQuaternions(const std::vector<Eigen::Quaterniond>& quaternions,
                                      const std::vector<double>& weights) {
  Eigen::Vector4d sum = Eigen::Vector4d::Zero();
  if (quaternions.empty()) return Eigen::Quaterniond::Identity();
  const Eigen::Vector4d first = quaternions.front().coeffs();
  for (size_t i = 0; i < quaternions.size(); ++i) {
    Eigen::Vector4d q = quaternions[i].coeffs();
    if (q.dot(first) < 0) q = -q;  // Eq. 6.10 needs <q_i, q_j> >= 0
    sum += (weights.empty() ? 1.0 : weights[i]) * q;
  }
  if (sum.norm() < 1e-12) return Eigen::Quaterniond::Identity();
  Eigen::Quaterniond out;
  out.coeffs() = sum.normalized();
  return out;
}

BodyPose RefineIcp(const BodyShape& shape, const BodyPose& start, const std::vector<IcpView>& views,
                   const IcpOptions& options) {
  BodyPose pose = start;
  std::vector<std::vector<Edge>> edges;
  for (const IcpView& v : views) edges.push_back(OutlineEdges(v.polygons));

  for (int iteration = 0; iteration < options.iterations; ++iteration) {
    for (int pass = 0; pass < 2; ++pass) {  // 0: body and upper arms, 1: forearms
      const PosedBody body = PoseBody(shape, pose);
      Vector3d shift_rhs = Vector3d::Zero();
      Eigen::Matrix3d shift_lhs = 1e-3 * Eigen::Matrix3d::Identity();
      bool shifted = false;
      std::array<std::vector<Vector3d>, kSegmentCount> axes;
      std::array<std::vector<double>, kSegmentCount> angles, weights;
      for (size_t c = 0; c < views.size(); ++c) {
        const IcpView& view = views[c];
        const auto ellipses = ProjectSegments(view, body);
        const Vector3d eye = view.camera.CenterInWorld();
        if (pass == 0) {
          // Body translation from the lower and upper body and the head.
          Vector2d t = Vector2d::Zero();
          double wsum = 0;
          for (int s : {kLowerBody, kUpperBody, kHeadSegment}) {
            for (const Pair& p : SegmentPairs(ellipses, s, edges[c], options)) {
              t += p.weight * (p.data - p.model);
              wsum += p.weight;
            }
          }
          if (wsum > 1.0) {
            t /= wsum;
            const Vector3d waist_in_cam = view.camera.cam_from_world * body.joints[kModelWaist];
            if (waist_in_cam.z() > 0.1) {
              const Eigen::Matrix3d world_from_cam = view.camera.cam_from_world.linear().transpose();
              const Vector3d d_world =
                  world_from_cam * Vector3d(t.x() * waist_in_cam.z() / view.camera.fx,
                                            t.y() * waist_in_cam.z() / view.camera.fy, 0.0);
              const Vector3d ray = (body.joints[kModelWaist] - eye).normalized();
              const Eigen::Matrix3d across = Eigen::Matrix3d::Identity() - ray * ray.transpose();
              shift_lhs += wsum * across;
              shift_rhs += wsum * d_world;
              shifted = true;
            }
          }
        }
        // Limb rotations about the joint's projection.
        for (int arm : {kRightUpperArm, kLeftUpperArm}) {
          const int segment = arm + pass;
          const Vector3d joint3d = body.frames[segment].translation();
          const Vector3d joint_in_cam = view.camera.cam_from_world * joint3d;
          if (joint_in_cam.z() <= 0.1) continue;
          const Eigen::Vector3d h = view.projection * joint3d.homogeneous();
          const Vector2d pivot = h.head<2>() / h.z();
          double cross = 0, dot = 0, wsum = 0;
          for (const Pair& p : SegmentPairs(ellipses, segment, edges[c], options)) {
            const Vector2d a = p.model - pivot, b = p.data - pivot;
            cross += p.weight * (a.x() * b.y() - a.y() * b.x());
            dot += p.weight * a.dot(b);
            wsum += p.weight;
          }
          if (wsum < 1.0) continue;
          // An image rotation from +u towards +v is a rotation about the
          // camera's forward axis, here the ray through the joint.
          axes[segment].push_back((joint3d - eye).normalized());
          angles[segment].push_back(std::atan2(cross, dot));
          weights[segment].push_back(wsum);
        }
      }
      if (pass == 0 && shifted) {
        const Vector3d shift = shift_lhs.lu().solve(shift_rhs);
        pose.dof[kDofX] += shift.x();
        pose.dof[kDofY] += shift.y();
        pose.dof[kDofZ] += shift.z();
      }
      for (int arm : {kRightUpperArm, kLeftUpperArm}) {
        const int segment = arm + pass;
        if (axes[segment].empty()) continue;
        const Vector3d upper = (body.frames[arm + 1].translation() - body.frames[arm].translation()).normalized();
        const int tip = arm == kRightUpperArm ? kModelRightHandTip : kModelLeftHandTip;
        const Vector3d fore = (body.joints[tip] - body.frames[arm + 1].translation()).normalized();
        const Vector3d limb = pass == 0 ? upper : fore;
        const Vector3d omega = CombineRotations(axes[segment], angles[segment], weights[segment], limb,
                                                options.least_squares);
        if (omega.norm() < 1e-9) continue;
        const Eigen::Matrix3d rotation = Eigen::AngleAxisd(omega.norm(), omega.normalized()).toRotationMatrix();
        if (pass == 0) {
          SetArmDirections(shape, &pose, arm, rotation * upper, rotation * fore);
        } else {
          SetArmDirections(shape, &pose, arm, upper, rotation * fore);
        }
      }
    }
    ClampToJointLimits(&pose);
  }
  return pose;
}

}  // namespace irbench
