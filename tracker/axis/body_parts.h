#pragma once
// Body parts from the 2D axis graph (thesis 3.3): arms are thin axis segments
// beside the torso and above the waist, the torso is the thick horizontal scans
// of the central bulk, the head the highest axis points above the torso. The
// rules assume an upright person seen by a roughly level camera (image up is
// world up); an overhead camera's silhouette does not fit them.

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <optional>
#include <vector>

#include "tracker/axis/axis_points.h"

namespace irbench {

enum class BodyPart {
  kNone = 0,
  kHead,
  kTorso,
  kLeftImageArm,   // the arm on the image's left of the torso (2D only)
  kRightImageArm,  // the arm on the image's right of the torso (2D only)
  kArm,            // a 3D arm point (which body side is left to the pose fit)
};
const char* BodyPartName(BodyPart part);

struct BodyPartOptions {
  int min_blob_area_px = 150;  // a smaller largest blob: no person
  // Torso rows: horizontal runs through the torso column at least this
  // fraction of the torso's width (twice the silhouette's largest inscribed
  // radius).
  double torso_min_width_fraction = 0.6;
  // Arms: kept axis points with diameter_px at most this fraction of the
  // torso width (median torso run).
  double arm_max_width_fraction = 0.6;
  // Arms lie above this fraction of the body's image height, measured down
  // from the top of the head (0.55: about the crotch, so hanging hands count).
  double arm_max_height_fraction = 0.55;
  // The torso band that arms must lie outside: the torso's median centre
  // column +- this fraction of the torso width.
  double torso_band_fraction = 0.5;
  // Arm points of different scan directions are linked when their midpoints are
  // within this many pixels.
  double link_px = 2.0;
  int min_arm_points = 6;  // smaller arm components are dropped
  void Check() const;      // throws InputError naming the field
};

struct BodyParts2d {
  std::vector<BodyPart> labels;  // one per AxisGraph point
  // Indices into AxisGraph::points. Arms ordered by distance from the top of the
  // torso (shoulder outwards); torso and head by row, top first.
  std::vector<int> head, torso, left_arm, right_arm;
  Eigen::Vector2d torso_center_px = Eigen::Vector2d::Zero();  // largest inscribed circle
  double torso_width_px = 0;   // median torso run
  double torso_column_px = 0;  // median torso midpoint u
  int head_top_row = 0, torso_top_row = 0, waist_row = 0, arm_max_row = 0;
};

// Thesis 3.3: labels the axis points of `graph` (from ExtractAxisPoints on the
// same `silhouette`, CV_8UC1) on the silhouette's largest blob. Returns
// nullopt when there is no blob of min_blob_area_px. Pixels, image frame.
std::optional<BodyParts2d> SegmentBodyParts(const cv::Mat& silhouette,
                                            const AxisGraph& graph,
                                            const BodyPartOptions& options = {});

}  // namespace irbench
