#pragma once
// Keyframed motion (motions/*.json): poses at given times, interpolated with
// eased spherical interpolation, so `render` has motion before the motion
// library exists. Format in docs/formats.md.

#include <filesystem>
#include <string>
#include <vector>

#include "sim/body/skeleton.h"

namespace irbench {

struct Keyframe {
  double t = 0;  // seconds
  Pose pose;
};

class KeyframeMotion {
 public:
  KeyframeMotion(std::string name, std::vector<Keyframe> keys);

  const std::string& name() const { return name_; }
  double duration() const { return keys_.back().t; }
  // The pose at time t (held before the first and after the last key).
  Pose At(double t) const;

 private:
  std::string name_;
  std::vector<Keyframe> keys_;
};

// Loads a keyframe file. Joint rotations are [x, y, z] degrees in the thesis's
// ZXY order; joints a key does not list are at their bind (T-pose) rotation.
KeyframeMotion LoadKeyframes(const std::filesystem::path& path);

}  // namespace irbench
