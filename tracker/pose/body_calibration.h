#pragma once
// Per-user body calibration (thesis 6.1, model configuration; 6.1.2, "Model
// Scaling by 3D Height"): the ellipsoid model's size for the user the pose
// tracker follows. When a user enters, the model takes the voxel hull's top
// for its height; over the first tracked frames the height is the median of
// the hull's tops and the girth the median of the best girths against the
// silhouettes, while the arms are below the shoulders; the arm thickness is
// the median diameter of the 3D arm axis points. The thesis configures the
// model "only ... at the start of body tracking", as here.
//
// The shape is the tracker's (PoseTracker keeps it); these functions update
// it and say by what ratio the particles' waist heights must scale.

#include <Eigen/Core>
#include <array>
#include <functional>
#include <optional>
#include <vector>

#include "tracker/body_model/body_model.h"
#include "tracker/pose/pose_tracker_options.h"

namespace irbench {

// One arm's measurement for MeasureShoulderWidth: the distance (metres) from
// the midpoint `centre` of the model's shoulders, along the unit `lateral`
// direction from its left shoulder to its right (negated for the left arm),
// at which the arm's axis points `points` (metres from the model's shoulder
// `shoulder`) cross the shoulders' line; nullopt unless the arm is seen held
// straight and away from the body: at least 5 points beyond 15 cm of the
// shoulder, reaching 45 cm from where they cross it, within 2 cm (rms) of
// one line, which passes within 5 cm of the shoulders' line and at least 45
// degrees from it (an arm held out sideways gives no crossing).
std::optional<double> ShoulderOffsetFromArm(const std::vector<Eigen::Vector3d>& points,
                                            const Eigen::Vector3d& shoulder, const Eigen::Vector3d& centre,
                                            const Eigen::Vector3d& lateral, bool left);

class BodyCalibration {
 public:
  // Reads height_frames and the arm_thickness_* settings of `options`.
  explicit BodyCalibration(const PoseTrackerOptions& options) : options_(options) {}

  // The log-likelihood (thesis 6.3.1) of a pose for a body shape.
  using ShapeScore = std::function<double(const BodyShape&, const BodyPose&)>;

  // A new user: forgets every measurement and returns the first model, as
  // tall as the voxel hull's top `top_m` (metres, clamped to 1.2-2.2), girth 1.
  BodyShape Start(double top_m);

  // Has a height been measured (MeasureHeightAndGirth) since Start?
  bool height_measured() const { return !heights_.empty(); }
  // Does MeasureHeightAndGirth still take measurements? Until height_frames
  // are in, and while the ones in were taken with cameras left out.
  bool measuring_height() const {
    return static_cast<int>(heights_.size()) < options_.height_frames || partial_views_;
  }
  // Would MeasureHeightAndGirth take this frame's measurement, were its
  // other conditions met, with `all_views` or a camera left out? False with
  // a camera left out once a frame was measured with all views, and once
  // height_frames are in (unless they were taken with cameras left out and
  // all views are back): the frame's feet then need no looking at.
  bool takes_height_sample(bool all_views) const {
    if (all_views && partial_views_) return true;
    if (!all_views && !heights_.empty() && !partial_views_) return false;
    return static_cast<int>(heights_.size()) < options_.height_frames;
  }

  // Until the height is measured, a model more than height_top_match off the
  // hull's top `top_m` (metres, clamped to 1.2-2.2) takes the top's height: updates
  // `shape` and returns the ratio of the new height to the old, by which the
  // particles' waist heights scale; nullopt when the model is kept.
  std::optional<double> MatchHullTop(double top_m, BodyShape* shape) const;

  // Thesis 6.1.2: one frame's measurement of the height (the hull's top
  // `top_m`, metres) and the girth (the best against the silhouettes by
  // `score`, the estimate `estimate` upright) while `tracking`, the
  // estimate's arms are below its shoulders, it stands upright (its trunk
  // within height_max_lean_deg of the vertical, its waist at least
  // height_min_waist of a standing model's as tall as `top_m`) and
  // `feet_on_floor`, over the first height_frames such frames. Updates
  // `shape` to the medians and returns the ratio by which the waist heights
  // scale; nullopt when nothing was measured. Unless `all_views` (a camera
  // was left out of the frame-set: its hull, carved by fewer views, stands
  // taller) the measurement is provisional: taken only while there are no
  // others, and all of them dropped at the first frame measured with all
  // views, from which the height_frames are counted again.
  std::optional<double> MeasureHeightAndGirth(bool tracking,
                                              const BodyPose& estimate,
                                              double top_m,
                                              bool feet_on_floor,
                                              bool all_views,
                                              const ShapeScore& score,
                                              BodyShape* shape);

  // The arms' thickness from this frame's 3D arm axis points' diameters
  // `arm_diameters_m` (metres) while `tracking`, over the first
  // arm_thickness_frames frames that have them; `shape` rescaled once
  // arm_thickness_min_points are in.
  void MeasureArmThickness(bool tracking,
                           const std::vector<double>& arm_diameters_m,
                           BodyShape* shape);

  // Thesis 6.1.1's per-user proportion, the shoulder width, from this
  // frame's 3D arm axis points by side (right, left; ArmPointsBySide) while
  // `tracking` with the estimate `body`: an arm held straight and away from
  // the body is a line of axis points through its shoulder joint, which
  // meets the line through the model's shoulders where that joint is
  // (ShoulderOffsetFromArm). `shape` takes the median of the first
  // shoulder_samples such measurements once shoulder_min_samples are in.
  // Does MeasureShoulderWidth still take measurements?
  bool measuring_shoulders() const { return static_cast<int>(shoulder_offsets_.size()) < options_.shoulder_samples; }
  void MeasureShoulderWidth(bool tracking, const PosedBody& body,
                            const std::array<std::vector<Eigen::Vector3d>, 2>& arm_points, BodyShape* shape);

  // The model for a height (metres) and girth, its arms as thick and its
  // shoulders as wide as measured.
  BodyShape ShapeFor(double height_m, double girth) const;

 private:
  PoseTrackerOptions options_;
  std::vector<double> heights_, girths_;
  bool partial_views_ = false;  // heights_ were measured with cameras left out
  std::vector<double> shoulder_offsets_;  // metres from the midline, per measurement
  double shoulder_width_ = 1.0;           // their median over the fixed proportion; 1 until measured
  std::vector<double> arm_diameters_;  // metres, from the 3D arm axis points
  int arm_frames_ = 0;                 // tracked frames that gave them
  double arm_diameter_m_ = 0;          // their median; 0 until measured
};

}  // namespace irbench
