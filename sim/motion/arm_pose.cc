#include "sim/motion/arm_pose.h"

#include <algorithm>
#include <cmath>

namespace irbench {
namespace {
constexpr double kArmDeg = M_PI / 180.0;
}  // namespace

Eigen::Vector3d BindArmDir(int side) { return Eigen::Vector3d(side, 0, 0); }

// Upper arm along d_u, forearm along d_f (chest frame), bending as a hinge.
ArmPose ArmFromDirections(int side, const Eigen::Vector3d& d_u_in, const Eigen::Vector3d& d_f_in) {
  const Eigen::Vector3d d_u = d_u_in.normalized(), d_f = d_f_in.normalized();
  ArmPose arm;
  const Eigen::Vector3d n = d_u.cross(d_f);
  if (n.norm() < 1e-6) {
    arm.shoulder = Eigen::Quaterniond::FromTwoVectors(BindArmDir(side), d_u);
    arm.elbow_deg = 0;
    return arm;
  }
  // Right arm: R x = d_u, R z = n; left arm: R x = -d_u, R z = -n (its
  // flexion is about -z).
  Eigen::Matrix3d r;
  const Eigen::Vector3d x = side * d_u, z = side * n.normalized();
  r << x, z.cross(x), z;
  arm.shoulder = Eigen::Quaterniond(r);
  arm.elbow_deg = std::acos(std::clamp(d_u.dot(d_f), -1.0, 1.0)) / kArmDeg;
  return arm;
}

// Arm direction by azimuth (0: straight out to the side, 90: forward) and
// elevation (0: horizontal, 90: up), the forearm bent by `elbow` degrees
// towards `bend` (default: up, or forward when the arm points up or down).
ArmPose ArmAngles(int side, double az, double el, double elbow, const Eigen::Vector3d& bend) {
  const Eigen::Vector3d d_u(side * std::cos(el * kArmDeg) * std::cos(az * kArmDeg),
                            std::cos(el * kArmDeg) * std::sin(az * kArmDeg), std::sin(el * kArmDeg));
  if (std::abs(elbow) < 1e-9) return ArmFromDirections(side, d_u, d_u);
  Eigen::Vector3d b = bend.norm() > 0 ? bend : (std::abs(el) > 60 ? Eigen::Vector3d(0, 1, 0) : Eigen::Vector3d(0, 0, 1));
  b = (b - d_u * d_u.dot(b)).normalized();
  const Eigen::Vector3d d_f = std::cos(elbow * kArmDeg) * d_u + std::sin(elbow * kArmDeg) * b;
  return ArmFromDirections(side, d_u, d_f);
}

// The resting arm: hanging, slightly away from the body, the elbow a little bent.
ArmPose RestArm(int side, const MotionStyle& style) {
  return ArmAngles(side, 0, -(90 - style.rest_abduction_deg), 12, Eigen::Vector3d(0, 1, 0));
}

ArmPose Blend(const ArmPose& a, const ArmPose& b, double w) {
  return {a.shoulder.slerp(w, b.shoulder), a.elbow_deg + w * (b.elbow_deg - a.elbow_deg)};
}

// Two-bone reach: the wrist at `wrist` (chest frame, relative to the
// shoulder), the elbow bending away from `pole`.
ArmPose ArmReach(int side, const Skeleton& sk, const Eigen::Vector3d& wrist, const Eigen::Vector3d& pole) {
  const int sh = side > 0 ? kRightShoulder : kLeftShoulder;
  const double a = (sk.bind_position[sh + 1] - sk.bind_position[sh]).norm();
  const double b = (sk.bind_position[sh + 2] - sk.bind_position[sh + 1]).norm();
  const double r = std::clamp(wrist.norm(), std::abs(a - b) + 1e-4, a + b - 1e-4);
  const Eigen::Vector3d to = wrist.normalized();
  const double alpha = std::acos(std::clamp((a * a + r * r - b * b) / (2 * a * r), -1.0, 1.0));
  Eigen::Vector3d perp = pole - to * to.dot(pole);
  perp.normalize();
  const Eigen::Vector3d d_u = std::cos(alpha) * to + std::sin(alpha) * perp;
  const Eigen::Vector3d elbow = a * d_u;
  return ArmFromDirections(side, d_u, to * r - elbow);
}

int PostureAtomIndex(const std::string& name) {
  if (name.size() == 2 && name[0] == 'A' && name[1] >= '0' && name[1] <= '4') return name[1] - '0';
  return -1;
}

const char* const kPostureAtomNames = "A0 rest, A1 horizontal, A2 overhead, A3 diagonal up, A4 diagonal down";

// The five atom postures of one arm (docs/motion.md).
ArmPose Atom(int atom, int side, const MotionStyle& style) {
  switch (atom) {
    case 1: return ArmAngles(side, 0, 0);        // A1 horizontal, out to the side
    case 2: return ArmAngles(side, 10, 80, 5);   // A2 overhead
    case 3: return ArmAngles(side, 0, 45);       // A3 diagonal up
    case 4: return ArmAngles(side, 0, -45);      // A4 diagonal down
    default: return RestArm(side, style);        // A0 rest
  }
}

ArmPose AtomBlend(std::array<double, 5> weights, int side, const MotionStyle& style) {
  double sum = 0;
  for (const double w : weights) sum += w;
  weights[0] += std::max(0.0, 1.0 - sum);
  const ArmPose rest = Atom(0, side, style);
  Eigen::Vector4d q = Eigen::Vector4d::Zero();
  double elbow = 0, total = 0;
  for (int atom = 0; atom <= 4; ++atom) {
    if (weights[atom] <= 0) continue;
    const ArmPose a = Atom(atom, side, style);
    const double sign = a.shoulder.coeffs().dot(rest.shoulder.coeffs()) < 0 ? -1 : 1;
    q += sign * weights[atom] * a.shoulder.coeffs();
    elbow += weights[atom] * a.elbow_deg;
    total += weights[atom];
  }
  ArmPose arm;
  arm.shoulder = Eigen::Quaterniond(q.normalized());
  arm.elbow_deg = elbow / total;
  return arm;
}

}  // namespace irbench
