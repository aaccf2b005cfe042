#pragma once
// Keyframed motion (motions/*.json): poses at given times, interpolated with
// eased spherical interpolation, so `render` has motion before the motion
// library exists. Format in docs/formats.md.

#include <filesystem>
#include <string>
#include <vector>

#include "sim/body/skeleton.h"
#include "sim/motion/motion_source.h"

namespace irbench {

struct Keyframe {
  double t = 0;  // seconds
  Pose pose;
};

class KeyframeMotion : public MotionSource {
 public:
  KeyframeMotion(std::string name, std::vector<Keyframe> keys,
                 std::vector<MotionEvent> events = {});

  double Duration() const override { return keys_.back().t; }
  // The pose at time t (held before the first and after the last key).
  Pose At(double t) const override;
  std::vector<MotionEvent> Events() const override { return events_; }
  const std::vector<Keyframe>& keys() const { return keys_; }

 private:
  std::vector<Keyframe> keys_;
  std::vector<MotionEvent> events_;
};

// Loads a keyframe file. Joint rotations are [x, y, z] degrees in the thesis's
// ZXY order; joints a key does not list are at their bind (T-pose) rotation.
KeyframeMotion LoadKeyframes(const std::filesystem::path& path);

}  // namespace irbench
