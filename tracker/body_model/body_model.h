#pragma once
// The tracker's articulated body (thesis 6.1, Fig. 6.1): seven ellipsoid
// segments (lower body, upper body, head, upper and lower arms) joined by six
// joints (waist, neck, shoulders, elbows), 21 degrees of freedom, scaled to the
// user's height (6.1.2). The sim never renders this model: it poses skinned
// meshes (architecture.md, "no inverse crime").
//
// Frames: world metres, z up (thesis 6.1). The body frame has x to the person's
// right, y forward (where they face), z up; a body rotation of zero faces +y.
//
// The 21 parameters (BodyPose::dof), angles in radians:
//   0-2   waist position in the world (x, y, z)
//   3-5   body rotation, ZXY Euler angles: yaw about z, then pitch about x
//         (bowing forward is positive), then roll about y
//   6-8   waist: the upper body relative to the lower body, ZXY Euler angles
//   9-10  neck: azimuth and zenith of the head's axis in the upper-body frame
//         (zenith from straight up; azimuth 0 = to the right, pi/2 = forward)
//   11-13 right shoulder: azimuth, zenith and twist of the upper arm in the
//         upper-body frame (zenith from hanging straight down; azimuth 0 =
//         out to the side, pi/2 = forward); the twist turns the arm about its
//         own axis and with it the frame the elbow's angles are measured in
//   14-16 left shoulder: the same, mirrored (azimuth 0 = out to the left)
//   17-18 right elbow: azimuth and zenith of the forearm in the upper arm's
//         frame (zenith from straight on)
//   19-20 left elbow: the same, mirrored
// For axially symmetric arm segments the shoulder twist and the elbow azimuth
// overlap; the tracker keeps the twist at zero (the thesis notes the same
// symmetry and still counts 21 DOF).

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <string>

namespace irbench {

constexpr int kDofCount = 21;

enum BodySegment : int {
  kLowerBody = 0,
  kUpperBody,
  kHeadSegment,
  kRightUpperArm,
  kRightLowerArm,
  kLeftUpperArm,
  kLeftLowerArm,
  kSegmentCount
};
const char* BodySegmentName(int segment);

// Indices into BodyPose::dof.
enum BodyDof : int {
  kDofX = 0, kDofY, kDofZ,
  kDofYaw, kDofPitch, kDofRoll,
  kDofWaistZ, kDofWaistX, kDofWaistY,
  kDofNeckAzimuth, kDofNeckZenith,
  kDofRightShoulderAzimuth, kDofRightShoulderZenith, kDofRightShoulderTwist,
  kDofLeftShoulderAzimuth, kDofLeftShoulderZenith, kDofLeftShoulderTwist,
  kDofRightElbowAzimuth, kDofRightElbowZenith,
  kDofLeftElbowAzimuth, kDofLeftElbowZenith,
};
const char* BodyDofName(int dof);

// Segment lengths and ellipsoid sizes in metres. FromHeight scales one set of
// proportions (Drillis and Contini's segment lengths as fractions of stature,
// as tabulated by Winter, "Biomechanics and Motor Control of Human Movement")
// to a stature: thesis 6.1.2, "scale the articulated body model
// proportionally to the estimated height of the user". `girth` widens the
// torso's and legs' ellipsoids (and the arms' by its square root): the
// thesis notes height scaling alone fails "users who are too thin or obese".
// `arm_thickness` widens the arms' ellipsoids further: sleeves (a jacket)
// make arms thicker than a torso's girth says. `shoulder_width` scales the
// shoulder joints' distance from the midline (thesis 6.1.1's per-user
// proportion, measured by BodyCalibration).
struct BodyShape {
  double height_m = 1.75;
  double girth = 1.0;
  double arm_thickness = 1.0;
  double shoulder_width = 1.0;
  double waist_height_m = 0;     // waist joint above the floor, standing
  double torso_length_m = 0;     // waist joint to neck joint
  double shoulder_offset_m = 0;  // shoulder joint from the body's midline (x)
  double shoulder_height_m = 0;  // shoulder joint above the waist joint
  double head_offset_m = 0;      // neck joint to the head centre
  double upper_arm_m = 0;        // shoulder to elbow
  double forearm_m = 0;          // elbow to wrist
  double hand_m = 0;             // wrist to hand tip
  // The spine's joints lie behind the trunk's middle: the lower body's,
  // upper body's and head's ellipsoids sit this far forward (their frames'
  // y) of the joints they hang from (the head centre with its ellipsoid).
  // And the ankles, whose midpoint's floor point is the root, stand this far
  // behind the waist. Both from the truth joints' place in the sim's avatars
  // (docs/tracker.md): with the ellipsoids on the joints, the tracked waist
  // sat 2.7 cm ahead of the truth's.
  double spine_depth_m = 0;
  double ankle_setback_m = 0;
  // Ellipsoid semi-axes (x, y, z in the segment's frame; z along the segment).
  std::array<Eigen::Vector3d, kSegmentCount> radii;
  // Ellipsoid centre along the segment's z axis from its joint (negative:
  // hanging below it).
  std::array<double, kSegmentCount> center_along;

  static BodyShape FromHeight(double height_m, double girth = 1.0, double arm_thickness = 1.0,
                              double shoulder_width = 1.0);
};

struct BodyPose {
  std::array<double, kDofCount> dof{};
};

// One segment posed in the world: the points p with
// |diag(1/radii) * R^T (p - center)| = 1, where R = world_from_segment.
struct Ellipsoid {
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  Eigen::Matrix3d world_from_segment = Eigen::Matrix3d::Identity();
  Eigen::Vector3d radii = Eigen::Vector3d::Ones();
};

// The model's joints, the names of the truth (architecture.md): root is the
// floor point under the lower body's end, head the head centre (thesis 6.5's
// eye proxy).
enum ModelJoint : int {
  kModelRoot = 0,
  kModelWaist,
  kModelNeck,
  kModelHead,
  kModelLeftShoulder,
  kModelLeftElbow,
  kModelLeftWrist,
  kModelLeftHandTip,
  kModelRightShoulder,
  kModelRightElbow,
  kModelRightWrist,
  kModelRightHandTip,
  kModelJointCount
};
const char* ModelJointName(int joint);

struct PosedBody {
  std::array<Ellipsoid, kSegmentCount> segments;
  std::array<Eigen::Vector3d, kModelJointCount> joints;
  // world_from_frame of the body (lower body), upper body, head and the four
  // arm segments, each at its joint.
  std::array<Eigen::Isometry3d, kSegmentCount> frames;
};

// Forward kinematics (thesis 6.1).
PosedBody PoseBody(const BodyShape& shape, const BodyPose& pose);

// `a` wrapped to [-pi, pi), radians.
double WrapAngle(double a);

// The body yaw (DOF 3) of a body facing the unit direction `dir` (world xy;
// yaw 0 faces +y).
double YawFacing(const Eigen::Vector2d& dir);
// Its inverse: the unit direction (world xy) a body of yaw `yaw` faces.
Eigen::Vector2d FacingDirection(double yaw);

// ZXY Euler angles: Rz(z) * Rx(x) * Ry(y).
Eigen::Matrix3d RotationZxy(double z, double x, double y);
// Unit direction of (azimuth, zenith) in a segment's parent frame; `rest` is
// the zenith-0 direction (0, 0, 1) or (0, 0, -1) and `mirror` flips x (left limbs).
Eigen::Vector3d DirectionFromAngles(double azimuth, double zenith, double rest_z, bool mirror);
// The inverse: (azimuth, zenith) of unit `d` in the same convention.
Eigen::Vector2d AnglesFromDirection(const Eigen::Vector3d& d, double rest_z, bool mirror);

// Sets the angles of `arm` (kRightUpperArm or kLeftUpperArm) so that its upper
// arm points along `upper_dir_world` and its forearm along `fore_dir_world`
// (unit vectors, world frame), the shoulder twist zero.
void SetArmDirections(const BodyShape& shape, BodyPose* pose, int upper_arm_segment,
                      const Eigen::Vector3d& upper_dir_world, const Eigen::Vector3d& fore_dir_world);

// Joint limits as caps (thesis 6.3: joint constraints): each limb direction
// within a cone about a centre direction, the waist and body pitch/roll within
// ranges. Returns true when `pose` was inside; otherwise moves it to the
// nearest allowed angles and returns false.
bool ClampToJointLimits(BodyPose* pose);

// Standing with arms hanging, facing `yaw` (radians, 0 = +y) at floor point
// `root_xy`; and the thesis's scarecrow (arms out to the sides).
BodyPose StandingPose(const BodyShape& shape, const Eigen::Vector2d& root_xy, double yaw);
BodyPose ScarecrowPose(const BodyShape& shape, const Eigen::Vector2d& root_xy, double yaw);

}  // namespace irbench
