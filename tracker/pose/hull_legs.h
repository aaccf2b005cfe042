#pragma once
// The feet measured on the voxel hull: the root (the floor point under the
// ankles' midpoint, as the truth defines it) and the way the feet point.
//
// The model has no legs: its root is the floor point under its waist, a
// little behind it (BodyShape::ankle_setback_m). Real people do not stand
// that way. On CMU motion capture the waist stood 6-14 cm ahead of the
// ankles (knees bent, the shins leaning forward), and the tracked root was
// 8-15 cm off with a steady forward bias (issue 28). The hull's lower legs
// show where the ankles are: the centres of thin horizontal layers of the
// hull between the feet and the knees (both legs together; for the root
// each layer's centre is the midpoint of its two legs, split_legs) move
// along a line as the shins lean; the lowest layers' centre carried down
// that lean to the ankles' height is the ankles' midpoint. The feet, below
// it, reach forward of the ankles: the floor layer's centroid minus that
// point (from the layers' centroids) shows the way the person faces, which
// the silhouettes higher up cannot tell from its reverse.
//
// Measured against the truth's root on the first 240 frames of 8 renders
// (thesis preset; an offline replica of this estimate on the tracker's voxel
// PLYs): the library motions (p1, p3 demo, atom tour) 4.11 cm with the
// model's root -> 2.57-2.60 with this estimate blended 0.7-0.85 with it; the
// CMU clips (13_26, 01_01, 02_01 walk, 02_04, 141_16) 8.97 -> 5.2-5.3. A
// plain line through all layers, extrapolated, failed on the walk (8.0 ->
// 10.8 cm: a knee's kink, a swinging leg), hence the cap and the anchor.
// The mocap and full suites' figures: docs/tracker.md.

#include <optional>

#include <Eigen/Core>

#include "tracker/hull/voxel_hull.h"

namespace irbench {

struct HullLegsOptions {
  // The layers fitted: from low to high, fractions of the user's height
  // (0.11-0.25 h: above the feet's instep, below the knees and the hands of
  // hanging arms), each layer_m thick; at least min_layers with
  // min_layer_voxels voxels each.
  double low = 0.11;
  double high = 0.25;
  double layer_m = 0.02;
  int min_layers = 4;
  int min_layer_voxels = 3;
  // The height the line is extrapolated to: the ankle joints' (0.043-0.047 h
  // for the sim's persons; 0.045 h in anthropometric tables).
  double ankle = 0.045;
  // The lower leg's cross-section centre lies behind the ankle joint (the
  // calf): the estimate is moved this fraction of the height forward. On the
  // sim's parametric persons with vertical shins the layers' centroids stood
  // 2.1-2.9 cm behind the ankles' midpoint; 0.0085 h is 1.5 cm at 1.75 m.
  double calf = 0.0085;
  // Voxels within this horizontal distance of the model's root are legs.
  double radius_m = 0.45;
  // nullopt when the line leans more than root_max_slope (horizontal metres
  // per vertical metre: a crouch, a leg lifted high, an arm reaching down)
  // or the estimate lies farther than max_offset_m from the model's root;
  // the feet's direction (toes) only from a line leaning at most max_slope.
  // The lean carried down is capped (max_lean) either way, so a steep line
  // moves the root no more than a leaning one: with the root measured only
  // up to a slope of 1, a fifth of a walk's frames (a leg swinging) and of
  // a dance's or a jump's kept the model's root, 4-11 cm ahead of the
  // ankles on CMU motion capture (the 16 clips' first 8 s, 2026-12-07:
  // root 5.73 -> 5.36 cm with this alone, the library motions' 1.81 ->
  // 1.78, the harsh preset's 3.63 -> 3.70; docs/tracker.md).
  double max_slope = 1.0;
  double root_max_slope = 3.0;
  double max_offset_m = 0.3;
  // The lean carried down is capped at max_lean; it is carried from the
  // centroid of the layers below anchor_high of the height.
  double max_lean = 0.3;
  double anchor_high = 0.15;
  // The root reported: the model's root moved this share of the way to the
  // measured one (two estimates with their own errors; 0.7-1 measured alike,
  // 0.8 best on the library motions and the CMU clips together).
  double weight = 0.8;
  // The root from the layers' centres taken as the midpoints of their two
  // halves split along their principal axes, not the voxels' centroids: two
  // legs apart count alike however many voxels each holds. (The feet's
  // direction keeps the centroids.)
  bool split_legs = true;
  // The floor layer, for the feet's direction: 0 to feet of the height.
  double feet = 0.035;
  int min_feet_voxels = 10;
  void Check() const;  // throws InputError naming the field
};

struct HullLegs {
  Eigen::Vector3d root = Eigen::Vector3d::Zero();  // z = 0
  // The floor layer's centroid minus the ankles' midpoint (from the layers'
  // centroids, before the calf correction), metres; nullopt when the floor
  // layer has too few voxels or the layers' line leans more than max_slope.
  std::optional<Eigen::Vector2d> toes;
  int layers = 0;  // layers in the fit
};

// `model_root`: the model's root (where to look); `forward`: the direction the
// model faces (world; only x and y are used, need not be unit); `height_m`:
// the user's height.
std::optional<HullLegs> MeasureHullLegs(const VoxelHull& hull, const Eigen::Vector3d& model_root,
                                        const Eigen::Vector3d& forward, double height_m,
                                        const HullLegsOptions& options = {});

// The root reported frame by frame: the legs' (MeasureHullLegs) where they
// give one; elsewhere the model's root moved by the recent measured offset
// from it. How far a person's waist stands ahead of their ankles changes
// with their posture, not from frame to frame, so in a short gap of the
// legs' measures (a leg lifted high, a jump, the layers too thin) the
// offset of the frames before is a better guess than none: on CMU motion
// capture those frames' model roots stood 4-11 cm ahead of the truth's.
// The offset is kept in the lower body's frame (forward and to the left: it
// turns with the body), averaged over `smoothing_s` of measures (a noisy
// sensor's measures scatter: with the last one alone the harsh preset's
// root got worse) and fades over `memory_s` without one (the average too:
// a measure after a long gap is nearly the whole of it). Measured on the
// 16 CMU clips' first 8 s, 8 library scenarios and the harsh preset's demo
// (2026-12-07; docs/tracker.md): with root_max_slope, CMU root 5.73 ->
// 5.31 cm, library about 1 mm better, harsh 3.63 -> 3.67; the last offset
// held over 2 s gave the same on CMU but harsh 3.63 -> 4.48.
class RootOffsetMemory {
 public:
  RootOffsetMemory(double smoothing_s, double memory_s) : smoothing_s_(smoothing_s), memory_s_(memory_s) {}
  // The root for this frame. `model_root`: the model's; `forward`: the way
  // the lower body faces (world; x and y used, need not be unit; with none
  // on the floor the frame neither changes nor uses the average); `legs`:
  // this frame's measure, if any; `dt`: seconds since the last frame.
  Eigen::Vector3d Root(const Eigen::Vector3d& model_root, const Eigen::Vector3d& forward,
                       const std::optional<HullLegs>& legs, double dt);
  void Reset() {
    offset_ = Eigen::Vector2d::Zero();
    measured_ = false;
    gap_s_ = 0;
  }
  // The measures' average offset, forward and to the left (metres), as of
  // the last measure (before the fade since).
  const Eigen::Vector2d& offset() const { return offset_; }

 private:
  double smoothing_s_;
  double memory_s_;
  Eigen::Vector2d offset_ = Eigen::Vector2d::Zero();
  bool measured_ = false;  // a measure since the last Reset
  double gap_s_ = 0;       // seconds of frames without a measure since the last
};

// Are the feet on the floor: at least min_feet_voxels occupied voxels of
// the floor layer (centres below `feet` of the height `height_m`) within
// radius_m of `root` (horizontally)? A jump empties the floor layer.
bool FeetOnFloor(const VoxelHull& hull, const Eigen::Vector3d& root, double height_m,
                 const HullLegsOptions& options = {});

// How far above the floor the body's lowest part is: the bottom of the
// lowest occupied voxel within radius_m of `root` (horizontally), 0 when
// none lies below half the height `height_m` (nothing of the legs seen) or
// the hull reaches the floor. A jump lifts it by the feet's height.
double FloorGap(const VoxelHull& hull, const Eigen::Vector3d& root, double height_m,
                const HullLegsOptions& options = {});

// The top of the hull's column over `xy`: the layers from the one holding
// `from_z` upwards, each with an occupied voxel within radius_m of `xy`
// (horizontally), without a gap; the upper face of the last. nullopt when
// the layer at `from_z` holds none. A hand held over the head, apart from
// it, does not count; one laid on it does.
std::optional<double> HullColumnTop(const VoxelHull& hull, const Eigen::Vector2d& xy, double from_z,
                                    double radius_m);

}  // namespace irbench
