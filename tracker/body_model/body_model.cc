#include "tracker/body_model/body_model.h"

#include <algorithm>
#include <cmath>

namespace irbench {
namespace {

using Eigen::Matrix3d;
using Eigen::Vector3d;

// Upper-arm cone (thesis 6.1: joint limits as azimuth/zenith caps): the arm
// reaches up, down, out, forward and across the chest, not far behind the back.
const Vector3d kShoulderCapCenter = Vector3d(0.86, 0.51, 0.0).normalized();  // right arm, upper-body frame
constexpr double kShoulderCapRad = 120.0 * M_PI / 180.0;
constexpr double kElbowMaxZenith = 150.0 * M_PI / 180.0;
// The elbow bends one way. Carried from a hanging arm by the swing that
// raises it (the elbow's frame), a bent forearm points forward, inwards or
// out, never back: its component along the frame's y (forward for a
// hanging arm) stays above -kElbowMaxBackward. The truth of the 48 CMU
// scenarios of the full suite (24,500 arm-frames, the real elbows of eight
// avatars) lies below -0.1 in 0.7 % of arm-frames; the tracked arms did in
// about 11 % before this cap (docs/tracker.md).
constexpr double kElbowMaxBackward = 0.1;
constexpr double kNeckMaxZenith = 40.0 * M_PI / 180.0;
// Zenith 180 deg (an arm straight up) has no unique swing; stay just short.
constexpr double kMaxZenith = 178.0 * M_PI / 180.0;

bool ClampRange(double* v, double lo, double hi) {
  if (*v >= lo && *v <= hi) return true;
  *v = std::clamp(*v, lo, hi);
  return false;
}

// Minimal rotation taking unit `from` to unit `to`.
Matrix3d Swing(const Vector3d& from, const Vector3d& to) {
  return Eigen::Quaterniond::FromTwoVectors(from, to).toRotationMatrix();
}

// The forearm's backward component (kElbowMaxBackward) capped by turning
// the elbow's azimuth at its zenith to the nearer edge of the allowed range.
// The azimuth is measured in the twisted upper arm's frame: in the
// untwisted one it is azimuth + twist (the right arm) or azimuth - twist
// (the left, mirrored). Returns true when nothing changed.
bool CapElbowBackward(double twist, double zenith, double* azimuth, bool mirror) {
  const double s = std::sin(zenith);
  if (s <= kElbowMaxBackward) return true;
  const double offset = mirror ? -twist : twist;
  const double a = WrapAngle(*azimuth + offset);
  if (s * std::sin(a) >= -kElbowMaxBackward - 1e-12) return true;  // the edge itself is inside
  // Forbidden: a in (-pi + edge, -edge); sin(-edge) * s = -kElbowMaxBackward.
  const double edge = std::asin(kElbowMaxBackward / s);
  const double capped = a > -M_PI / 2 ? -edge : -M_PI + edge;
  *azimuth = WrapAngle(capped - offset);
  return false;
}

const Vector3d kDown(0, 0, -1);
const Vector3d kUp(0, 0, 1);

}  // namespace

double YawFacing(const Eigen::Vector2d& dir) { return std::atan2(-dir.x(), dir.y()); }

Eigen::Vector2d FacingDirection(double yaw) { return {-std::sin(yaw), std::cos(yaw)}; }

double WrapAngle(double a) {
  a = std::fmod(a + M_PI, 2 * M_PI);
  if (a < 0) a += 2 * M_PI;
  return a - M_PI;
}

const char* BodySegmentName(int segment) {
  static const char* names[] = {"lower_body",      "upper_body",     "head",          "right_upper_arm",
                                "right_lower_arm", "left_upper_arm", "left_lower_arm"};
  return segment >= 0 && segment < kSegmentCount ? names[segment] : "?";
}

const char* BodyDofName(int dof) {
  static const char* names[] = {"x",
                                "y",
                                "z",
                                "yaw",
                                "pitch",
                                "roll",
                                "waist_z",
                                "waist_x",
                                "waist_y",
                                "neck_azimuth",
                                "neck_zenith",
                                "right_shoulder_azimuth",
                                "right_shoulder_zenith",
                                "right_shoulder_twist",
                                "left_shoulder_azimuth",
                                "left_shoulder_zenith",
                                "left_shoulder_twist",
                                "right_elbow_azimuth",
                                "right_elbow_zenith",
                                "left_elbow_azimuth",
                                "left_elbow_zenith"};
  return dof >= 0 && dof < kDofCount ? names[dof] : "?";
}

const char* ModelJointName(int joint) {
  static const char* names[] = {"root",           "waist",         "neck",           "head",
                                "left_shoulder",  "left_elbow",    "left_wrist",     "left_hand_tip",
                                "right_shoulder", "right_elbow",   "right_wrist",    "right_hand_tip"};
  return joint >= 0 && joint < kModelJointCount ? names[joint] : "?";
}

BodyShape BodyShape::FromHeight(double h, double girth, double arm_thickness, double shoulder_width) {
  BodyShape s;
  s.height_m = h;
  s.girth = girth;
  s.arm_thickness = arm_thickness;
  s.shoulder_width = shoulder_width;
  s.waist_height_m = 0.600 * h;
  s.torso_length_m = 0.218 * h;
  // Half of Drillis and Contini's shoulder width (0.259), less the deltoid
  // over the joint: the sim's parametric avatars put their shoulder joints
  // at 0.105 too (times a person's shoulder_width, 0.92-1.12). At 0.100
  // the tracked shoulders sat 1.5-3 cm inside the truth's on p1, p3 and p5
  // (five demos, seeds 1-7: p5's shoulders 5.3 and 5.6 cm -> 4.3, 4.8).
  s.shoulder_offset_m = 0.105 * h * shoulder_width;
  s.spine_depth_m = 0.008 * h;
  s.ankle_setback_m = 0.010 * h;
  s.shoulder_height_m = 0.210 * h;
  s.head_offset_m = 0.117 * h;
  // The arm's bones between joint centres: Drillis and Contini's upper arm
  // (0.186) and forearm (0.146) run between bony landmarks (acromion,
  // radiale, stylion); the shoulder's joint centre lies below the acromion
  // and the elbow's above the radiale. The sim's avatars measure 0.172 and
  // 0.157 between their joints. With 0.186 and 0.146 the tracked elbows
  // sat 0.5-2.7 cm low and up to 3.4 cm ahead of the truth's (five demos,
  // seeds 1-3; over seeds 1-7 the arm joints' mean error 3.33 -> 3.17 cm,
  // p2_demo_theater5's pointing 3.37 -> 2.85 deg).
  s.upper_arm_m = 0.172 * h;
  s.forearm_m = 0.157 * h;
  s.hand_m = 0.108 * h;
  s.radii[kLowerBody] = Vector3d(0.095, 0.070, 0.300) * h;
  s.center_along[kLowerBody] = -0.300 * h;
  s.radii[kUpperBody] = Vector3d(0.095, 0.065, 0.130) * h;
  s.center_along[kUpperBody] = 0.110 * h;
  s.radii[kHeadSegment] = Vector3d(0.045, 0.055, 0.068) * h;
  s.center_along[kHeadSegment] = s.head_offset_m;
  for (int arm : {kRightUpperArm, kLeftUpperArm}) {
    // Centred on the bone (the forearm's with the hand), 1.13 and 1.06 times
    // as long: they overlap the joints.
    const double upper = s.upper_arm_m, lower = s.forearm_m + s.hand_m;
    s.radii[arm] = Vector3d(0.032 * h, 0.032 * h, 0.105 / 0.186 * upper);
    s.center_along[arm] = -0.5 * upper;
    s.radii[arm + 1] = Vector3d(0.025 * h, 0.025 * h, 0.135 / 0.254 * lower);
    s.center_along[arm + 1] = -0.5 * lower;
  }
  const double arm = std::sqrt(girth) * arm_thickness;
  const Eigen::Vector3d wide(girth, girth, 1.0), arm_wide(arm, arm, 1.0);
  for (int seg : {kLowerBody, kUpperBody}) s.radii[seg] = s.radii[seg].cwiseProduct(wide);
  for (int seg : {kRightUpperArm, kRightLowerArm, kLeftUpperArm, kLeftLowerArm}) {
    s.radii[seg] = s.radii[seg].cwiseProduct(arm_wide);
  }
  return s;
}

Matrix3d RotationZxy(double z, double x, double y) {
  return (Eigen::AngleAxisd(z, Vector3d::UnitZ()) * Eigen::AngleAxisd(x, Vector3d::UnitX()) *
          Eigen::AngleAxisd(y, Vector3d::UnitY()))
      .toRotationMatrix();
}

Vector3d DirectionFromAngles(double azimuth, double zenith, double rest_z, bool mirror) {
  const double s = std::sin(zenith);
  return Vector3d((mirror ? -1.0 : 1.0) * s * std::cos(azimuth), s * std::sin(azimuth), rest_z * std::cos(zenith));
}

Eigen::Vector2d AnglesFromDirection(const Vector3d& d_in, double rest_z, bool mirror) {
  const Vector3d d = d_in.normalized();
  const double zenith = std::acos(std::clamp(rest_z * d.z(), -1.0, 1.0));
  const double x = mirror ? -d.x() : d.x();
  const double azimuth = (std::abs(x) + std::abs(d.y()) < 1e-12) ? 0.0 : std::atan2(d.y(), x);
  return {azimuth, zenith};
}

PosedBody PoseBody(const BodyShape& shape, const BodyPose& pose) {
  const auto& q = pose.dof;
  PosedBody out;
  const Vector3d waist(q[kDofX], q[kDofY], q[kDofZ]);
  const Matrix3d world_from_body = RotationZxy(q[kDofYaw], q[kDofPitch], q[kDofRoll]);
  const Matrix3d world_from_upper = world_from_body * RotationZxy(q[kDofWaistZ], q[kDofWaistX], q[kDofWaistY]);
  const Vector3d neck = waist + world_from_upper * Vector3d(0, 0, shape.torso_length_m);
  const Matrix3d world_from_head =
      world_from_upper * Swing(kUp, DirectionFromAngles(q[kDofNeckAzimuth], q[kDofNeckZenith], 1.0, false));

  auto set_frame = [&](int segment, const Matrix3d& rotation, const Vector3d& origin) {
    Eigen::Isometry3d f = Eigen::Isometry3d::Identity();
    f.linear() = rotation;
    f.translation() = origin;
    out.frames[segment] = f;
  };
  set_frame(kLowerBody, world_from_body, waist);
  set_frame(kUpperBody, world_from_upper, waist);
  set_frame(kHeadSegment, world_from_head, neck);

  out.joints[kModelWaist] = waist;
  out.joints[kModelNeck] = neck;
  out.joints[kModelHead] = neck + world_from_head * Vector3d(0, shape.spine_depth_m, shape.head_offset_m);
  const Vector3d leg_end = waist + world_from_body * Vector3d(0, -shape.ankle_setback_m, -shape.waist_height_m);
  out.joints[kModelRoot] = Vector3d(leg_end.x(), leg_end.y(), 0.0);

  for (int side = 0; side < 2; ++side) {  // 0 right, 1 left
    const bool left = side == 1;
    const int ua = left ? kLeftUpperArm : kRightUpperArm;
    const int sh = left ? kDofLeftShoulderAzimuth : kDofRightShoulderAzimuth;
    const int el = left ? kDofLeftElbowAzimuth : kDofRightElbowAzimuth;
    const Vector3d shoulder =
        waist + world_from_upper * Vector3d((left ? -1 : 1) * shape.shoulder_offset_m, 0, shape.shoulder_height_m);
    const Matrix3d world_from_ua = world_from_upper *
                                   Swing(kDown, DirectionFromAngles(q[sh], q[sh + 1], -1.0, left)) *
                                   Eigen::AngleAxisd(q[sh + 2], Vector3d::UnitZ()).toRotationMatrix();
    const Vector3d elbow = shoulder + world_from_ua * Vector3d(0, 0, -shape.upper_arm_m);
    const Matrix3d world_from_la = world_from_ua * Swing(kDown, DirectionFromAngles(q[el], q[el + 1], -1.0, left));
    set_frame(ua, world_from_ua, shoulder);
    set_frame(ua + 1, world_from_la, elbow);
    out.joints[left ? kModelLeftShoulder : kModelRightShoulder] = shoulder;
    out.joints[left ? kModelLeftElbow : kModelRightElbow] = elbow;
    out.joints[left ? kModelLeftWrist : kModelRightWrist] = elbow + world_from_la * Vector3d(0, 0, -shape.forearm_m);
    out.joints[left ? kModelLeftHandTip : kModelRightHandTip] =
        elbow + world_from_la * Vector3d(0, 0, -(shape.forearm_m + shape.hand_m));
  }
  for (int s = 0; s < kSegmentCount; ++s) {
    Ellipsoid& e = out.segments[s];
    e.world_from_segment = out.frames[s].linear();
    const bool trunk = s == kLowerBody || s == kUpperBody || s == kHeadSegment;
    e.center = out.frames[s] * Vector3d(0, trunk ? shape.spine_depth_m : 0.0, shape.center_along[s]);
    e.radii = shape.radii[s];
  }
  return out;
}

void SetArmDirections(const BodyShape& shape, BodyPose* pose, int upper_arm_segment, const Vector3d& upper_dir_world,
                      const Vector3d& fore_dir_world) {
  (void)shape;
  auto& q = pose->dof;
  const bool left = upper_arm_segment == kLeftUpperArm;
  const int sh = left ? kDofLeftShoulderAzimuth : kDofRightShoulderAzimuth;
  const int el = left ? kDofLeftElbowAzimuth : kDofRightElbowAzimuth;
  const Matrix3d world_from_upper = RotationZxy(q[kDofYaw], q[kDofPitch], q[kDofRoll]) *
                                    RotationZxy(q[kDofWaistZ], q[kDofWaistX], q[kDofWaistY]);
  const Vector3d up_local = (world_from_upper.transpose() * upper_dir_world).normalized();
  const Eigen::Vector2d s = AnglesFromDirection(up_local, -1.0, left);
  q[sh] = s[0];
  q[sh + 1] = std::min(s[1], kMaxZenith);
  q[sh + 2] = 0.0;
  const Matrix3d world_from_ua = world_from_upper * Swing(kDown, DirectionFromAngles(q[sh], q[sh + 1], -1.0, left));
  const Eigen::Vector2d e = AnglesFromDirection(world_from_ua.transpose() * fore_dir_world, -1.0, left);
  q[el] = e[0];
  q[el + 1] = e[1];
}

bool ClampToJointLimits(BodyPose* pose) {
  auto& q = pose->dof;
  bool inside = true;
  // The lower body stands nearly upright (thesis 6.1: the legs are one
  // segment, the user mostly standing); bowing and leaning are the waist's.
  inside &= ClampRange(&q[kDofPitch], -0.1, 0.1);
  inside &= ClampRange(&q[kDofRoll], -0.1, 0.1);
  inside &= ClampRange(&q[kDofWaistZ], -0.8, 0.8);
  inside &= ClampRange(&q[kDofWaistX], -0.4, 1.0);
  inside &= ClampRange(&q[kDofWaistY], -0.5, 0.5);
  q[kDofYaw] = WrapAngle(q[kDofYaw]);
  // Azimuth/zenith pairs: a negative zenith is the same direction with the
  // azimuth turned half way round.
  auto normalise = [&](int az) {
    if (q[az + 1] < 0) {
      q[az + 1] = -q[az + 1];
      q[az] += M_PI;
    }
    if (q[az + 1] > M_PI) {
      q[az + 1] = 2 * M_PI - q[az + 1];
      q[az] += M_PI;
    }
    q[az] = WrapAngle(q[az]);
  };
  for (int az : {kDofNeckAzimuth, kDofRightShoulderAzimuth, kDofLeftShoulderAzimuth, kDofRightElbowAzimuth,
                 kDofLeftElbowAzimuth}) {
    normalise(az);
  }
  inside &= ClampRange(&q[kDofNeckZenith], 0.0, kNeckMaxZenith);
  inside &= ClampRange(&q[kDofRightElbowZenith], 0.0, kElbowMaxZenith);
  inside &= ClampRange(&q[kDofLeftElbowZenith], 0.0, kElbowMaxZenith);
  inside &= CapElbowBackward(q[kDofRightShoulderTwist], q[kDofRightElbowZenith], &q[kDofRightElbowAzimuth], false);
  inside &= CapElbowBackward(q[kDofLeftShoulderTwist], q[kDofLeftElbowZenith], &q[kDofLeftElbowAzimuth], true);
  for (int side = 0; side < 2; ++side) {
    const bool left = side == 1;
    const int sh = left ? kDofLeftShoulderAzimuth : kDofRightShoulderAzimuth;
    q[sh + 2] = WrapAngle(q[sh + 2]);
    inside &= ClampRange(&q[sh + 1], 0.0, kMaxZenith);
    // The cone, in the right arm's convention (mirroring is part of the angles).
    const Vector3d d = DirectionFromAngles(q[sh], q[sh + 1], -1.0, false);
    const double angle = std::acos(std::clamp(d.dot(kShoulderCapCenter), -1.0, 1.0));
    if (angle > kShoulderCapRad) {
      inside = false;
      const Vector3d axis = kShoulderCapCenter.cross(d);
      const Vector3d clamped =
          axis.norm() < 1e-9 ? Vector3d(0, 0, -1)
                             : Vector3d(Eigen::AngleAxisd(kShoulderCapRad, axis.normalized()) * kShoulderCapCenter);
      const Eigen::Vector2d a = AnglesFromDirection(clamped, -1.0, false);
      q[sh] = a[0];
      q[sh + 1] = a[1];
    }
  }
  return inside;
}

BodyPose StandingPose(const BodyShape& shape, const Eigen::Vector2d& root_xy, double yaw) {
  BodyPose p;
  // The waist stands ankle_setback_m ahead of the root.
  const Eigen::Vector2d waist_xy = root_xy + shape.ankle_setback_m * FacingDirection(yaw);
  p.dof[kDofX] = waist_xy.x();
  p.dof[kDofY] = waist_xy.y();
  p.dof[kDofZ] = shape.waist_height_m;
  p.dof[kDofYaw] = yaw;
  // Arms hang slightly away from the body.
  p.dof[kDofRightShoulderZenith] = p.dof[kDofLeftShoulderZenith] = 0.15;
  return p;
}

BodyPose ScarecrowPose(const BodyShape& shape, const Eigen::Vector2d& root_xy, double yaw) {
  BodyPose p = StandingPose(shape, root_xy, yaw);
  p.dof[kDofRightShoulderZenith] = p.dof[kDofLeftShoulderZenith] = M_PI / 2;
  return p;
}

}  // namespace irbench
