#pragma once
// BVH (Biovision hierarchy) files: reading with any channel order, CRLF, tabs
// and line-numbered errors; writing; forward kinematics into a MocapClip; and
// export of any motion on the canonical skeleton.

#include <Eigen/Core>
#include <filesystem>
#include <string>
#include <vector>

#include "sim/body/skeleton.h"
#include "sim/motion/mocap_clip.h"
#include "sim/motion/motion_source.h"

namespace irbench {

enum class BvhChannel { kXposition, kYposition, kZposition, kXrotation, kYrotation, kZrotation };

struct BvhJoint {
  std::string name;  // End Sites are named "<parent>_end"
  int parent = -1;
  Eigen::Vector3d offset = Eigen::Vector3d::Zero();
  std::vector<BvhChannel> channels;  // empty for End Sites
  bool end_site = false;
  int first_channel = 0;  // index of its first value in a frame line
};

struct BvhFile {
  std::string name;
  std::vector<BvhJoint> joints;  // parents before children, file order
  int channel_count = 0;
  double frame_time = 1.0 / 30.0;
  std::vector<std::vector<double>> frames;  // channel values; rotations in degrees
};

// Physical limits a BVH must respect; anything beyond is refused as input
// error (a crafted or corrupt file, not a capture).
// Joints nested deeper than this (a real skeleton has < 30 levels).
inline constexpr int kMaxBvhDepth = 256;
// |OFFSET| components and position channel values, in the file's units (CMU
// files are in inches or centimetres: 1e5 is a kilometre or more).
inline constexpr double kMaxBvhPosition = 1e5;
// |rotation channel value|, degrees (a joint that turned a million degrees).
inline constexpr double kMaxBvhRotationDeg = 1e6;
// Frame Time, seconds: at most one frame a minute, at least 1 MHz.
inline constexpr double kMinBvhFrameTime = 1e-6;
inline constexpr double kMaxBvhFrameTime = 60.0;

// Parses BVH text; errors name `file_name` and "line N". Refused: nesting
// deeper than kMaxBvhDepth; two joints with one name (End Sites are named
// "<parent>_end" and count too); non-finite numbers; positions and rotations
// beyond the limits above; a frame time outside [kMinBvhFrameTime,
// kMaxBvhFrameTime].
BvhFile ParseBvh(const std::string& text, const std::string& file_name);
BvhFile LoadBvh(const std::filesystem::path& path);
// Writes BVH text (tabs, LF, values with 6 decimals).
std::string WriteBvh(const BvhFile& bvh);

// Forward kinematics over every frame. A joint's local transform is its OFFSET
// plus its position channels, rotated by the product of its rotation channels
// in the order listed (the first listed is the leftmost factor).
MocapClip BvhToClip(const BvhFile& bvh);

// The rotation channels' values (degrees) for rotation q in the given channel
// order (the rotation channels only, e.g. Z X Y).
Eigen::Vector3d EulerDegrees(const Eigen::Quaterniond& q, const std::vector<BvhChannel>& order);

// Samples `motion` at `fps` on `skeleton` into a BVH of the canonical joints
// (names as in skeleton.h), Y up, metres, every joint `Zrotation Xrotation
// Yrotation` (the thesis's ZXY order), the root with positions first; End
// Sites at the head top, hand tips and toes (lengths from the skeleton's height).
// `frames` < 0: floor(duration × fps) + 1 frames.
BvhFile MotionToBvh(const MotionSource& motion, const Skeleton& skeleton, double fps, int frames = -1);

// World (z up, facing +y) <-> BVH's usual frame (y up, facing +z): the
// rotation (x, y, z) -> (-x, z, y), its own inverse.
Eigen::Matrix3d YUpFromWorld();

}  // namespace irbench
