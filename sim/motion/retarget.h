#pragma once
// Motion capture onto the canonical skeleton: BVH and ASF/AMC loading with the
// CMU conventions' quirks fixed, joint-name tables, and retargeting that keeps
// the source's bone directions (so upper-arm, forearm and head-to-hand
// directions are the source's) and joint twists, with the root path scaled by
// leg length. Rules in docs/motion.md.

#include <array>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "sim/body/skeleton.h"
#include "sim/motion/mocap_clip.h"
#include "sim/motion/motion_source.h"

namespace irbench {

// Bumped whenever Retarget or LoadMocap changes the motion a clip becomes, so
// that suites' render caches (keyed on their inputs' bytes) render mocap
// scenarios again. 2: the floor levelled and the converters' blend-in dropped.
inline constexpr int kRetargetRevision = 2;

// Loads a .bvh file, or an .amc file with its .asf (`asf` empty: the .asf
// beside it named by the subject, "16_01.amc" -> "16.asf", or by the stem).
// Fixes: raw amc2bvh files (CMU bone names) declaring 1/30 s per frame are
// 120 Hz captures (frame time set to 1/120 s); a synthetic start is dropped:
// a first frame added by converters (a T-pose or rest frame, seen as a jump of
// more than 10° that is 5x larger than the next frame's) and the blend into the
// capture that some converters put after it (leading frames where some joint
// turns more than 4x the clip's median turn per frame and 5°; at most 0.1 s).
MocapClip LoadMocap(const std::filesystem::path& path, const std::filesystem::path& asf = {});

// "mb", "daz", "3dsmax", "cmu", "irbench", or "" (unknown).
std::string DetectConvention(const MocapClip& clip);

// Canonical joint name (skeleton.h) -> the clip's joint name, for a convention
// (plus "head_top" for the head's end); an entry may list alternatives
// separated by '|' ("root|hip").
std::map<std::string, std::string> JointMapFor(const std::string& convention);

struct RetargetOptions {
  // Where frame 0's pelvis stands on the floor (world x, y), and the heading
  // (degrees about +z; 0 keeps the clip's first-frame facing turned to +y).
  Eigen::Vector2d place_at = Eigen::Vector2d::Zero();
  double heading_deg = 0;
  std::map<std::string, std::string> joint_map_overrides;
};

// The source's rest-pose frame turned into the world's: its up (the file's
// axis nearest the pelvis-to-head line), left (right hip to left hip, levelled)
// and forward (left x up) go to +z, -x, +y.
Eigen::Matrix3d WorldFromSource(const MocapClip& clip, const std::map<std::string, std::string>& map);

class RetargetedMotion : public MotionSource {
 public:
  RetargetedMotion(std::string name, double frame_time, std::vector<Pose> poses);
  Pose At(double t) const override;
  double Duration() const override { return (poses_.size() - 1) * frame_time_; }
  double frame_time() const { return frame_time_; }
  // The world rotation applied to the source (WorldFromSource, then heading),
  // the scale of its root path, and the joint table used, for checks.
  Eigen::Matrix3d world_from_source;
  double scale = 1;
  std::array<int, kJointCount> source_joint{};  // clip joint per canonical joint (-1: none)
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();  // world = scale·R·p + translation

 private:
  double frame_time_;
  std::vector<Pose> poses_;
};

// Retargets a clip onto a skeleton. InputError if a needed joint (pelvis, hips,
// knees, ankles, spine, chest, neck, head, shoulders, elbows, wrists) is missing.
std::shared_ptr<RetargetedMotion> Retarget(const MocapClip& clip, const Skeleton& skeleton,
                                           const RetargetOptions& options = {});

}  // namespace irbench
