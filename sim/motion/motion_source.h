#pragma once
// Motion: the canonical skeleton's pose at any time t, from any source —
// keyframes, the procedural library, retargeted BVH or ASF/AMC capture — and
// compositions of them (sequence with crossfades, loop, left/right mirror, time
// warp, joint layers). Sources also carry their events (a gesture's span, an
// arm aimed at a screen target), from which the truth labels are written.

#include <memory>
#include <string>
#include <vector>

#include "sim/body/skeleton.h"

namespace irbench {

// Something the motion does over [start, end] seconds: kind "gesture" (value:
// the gesture name) or "point" (value: the screen target the arm is aimed at,
// side: "left"/"right"; the span covers only the settled hold).
struct MotionEvent {
  std::string kind;
  std::string value;
  std::string side;  // "left", "right" or "" for both / the body
  double start = 0;
  double end = 0;
};

class MotionSource {
 public:
  explicit MotionSource(std::string name) : name_(std::move(name)) {}
  virtual ~MotionSource() = default;

  const std::string& name() const { return name_; }
  // The pose at time t in [0, Duration()]; held outside it.
  virtual Pose At(double t) const = 0;
  virtual double Duration() const = 0;
  // Events in this source's time, sorted by start.
  virtual std::vector<MotionEvent> Events() const { return {}; }

 private:
  std::string name_;
};

using MotionPtr = std::shared_ptr<const MotionSource>;

// Blends two poses: root offsets linearly, rotations by slerp; w = 0 gives a.
Pose BlendPoses(const Pose& a, const Pose& b, double w);

// Mirrors a pose left/right across the body's sagittal plane (world x -> -x):
// left and right joints swap, rotations are reflected.
Pose MirrorPose(const Pose& pose);

// Plays sources one after the other; item k starts `crossfade_s` before item
// k-1 ends and blends in over that overlap (smoothstep). Positions are not
// re-based: each source's root offset is absolute (stage coordinates). Each
// item's events are clipped to the time it owns: from the middle of its
// crossfade in to the middle of its crossfade out.
class SequenceMotion : public MotionSource {
 public:
  struct Item {
    MotionPtr source;
    double crossfade_s = 0;  // overlap with the previous item
  };
  SequenceMotion(std::string name, std::vector<Item> items);
  Pose At(double t) const override;
  double Duration() const override { return duration_; }
  std::vector<MotionEvent> Events() const override;
  // Start time of item k.
  double StartOf(size_t k) const { return start_[k]; }

 private:
  std::vector<Item> items_;
  std::vector<double> start_;
  double duration_ = 0;
};

// Repeats a source `count` times (a crossfade of `crossfade_s` at each seam).
MotionPtr LoopMotion(MotionPtr source, int count, double crossfade_s);

// The source mirrored left/right (MirrorPose, events' sides swapped).
class MirrorMotion : public MotionSource {
 public:
  explicit MirrorMotion(MotionPtr source);
  Pose At(double t) const override { return MirrorPose(source_->At(t)); }
  double Duration() const override { return source_->Duration(); }
  std::vector<MotionEvent> Events() const override;

 private:
  MotionPtr source_;
};

// Time warp: output time t plays source time f(t), f piecewise linear through
// (t_out, t_source) points, increasing in both. `Speed` gives f(t) = s·t.
class TimeWarpMotion : public MotionSource {
 public:
  TimeWarpMotion(MotionPtr source, std::vector<std::pair<double, double>> points);
  static MotionPtr Speed(MotionPtr source, double speed);
  Pose At(double t) const override { return source_->At(SourceTime(t)); }
  double Duration() const override { return points_.back().first; }
  std::vector<MotionEvent> Events() const override;
  double SourceTime(double t) const;
  double OutputTime(double source_t) const;

 private:
  MotionPtr source_;
  std::vector<std::pair<double, double>> points_;
};

// Joint layers: the base's pose, with the listed joints' rotations taken from
// the overlay (e.g. arms from a gesture over a walk).
class LayerMotion : public MotionSource {
 public:
  LayerMotion(MotionPtr base, MotionPtr overlay, std::vector<int> joints);
  Pose At(double t) const override;
  double Duration() const override { return base_->Duration(); }
  std::vector<MotionEvent> Events() const override;

 private:
  MotionPtr base_, overlay_;
  std::vector<int> joints_;
};

// Shifts a source in time by `delay_s` (holding its first pose before).
class DelayMotion : public MotionSource {
 public:
  DelayMotion(MotionPtr source, double delay_s)
      : MotionSource(source->name()), source_(std::move(source)), delay_(delay_s) {}
  Pose At(double t) const override { return source_->At(t - delay_); }
  double Duration() const override { return source_->Duration() + delay_; }
  std::vector<MotionEvent> Events() const override;

 private:
  MotionPtr source_;
  double delay_;
};

// The joints of one arm (clavicle, shoulder, elbow, wrist); side +1 right, -1 left.
std::vector<int> ArmJoints(int side);

}  // namespace irbench
