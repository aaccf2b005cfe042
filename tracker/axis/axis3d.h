#pragma once
// 3D body axis points from 2D axes (thesis 4.4.2): for each pair of cameras, the
// epipolar line of an axis point of one image meets the same part's axis in the
// other image; the two pixels triangulate a 3D axis point. Camera pairs whose
// epipolar lines run along the 2D axis (the limb nearly in the plane through
// both camera centres) are skipped there; 3D points whose projection misses a
// silhouette are dropped. World frame: metres, z up.

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <vector>

#include "geometry/camera.h"
#include "tracker/axis/axis_points.h"
#include "tracker/axis/body_parts.h"

namespace irbench {

// One camera's input to the 3D stage.
struct AxisView {
  Camera camera;
  cv::Mat silhouette;  // CV_8UC1, foreground > 0, the camera's size
  AxisGraph graph;     // ExtractAxisPoints(silhouette)
  // One per graph point; kNone for points the stage ignores. Empty: the view
  // only checks other views' 3D points against its silhouette.
  std::vector<BodyPart> labels;
  // Optional, CV_32FC1 of the camera's size: each pixel's distance to the
  // nearest silhouette pixel (> 0), when the caller has it; computed from
  // `silhouette` when empty. For 0/255 masks DistanceToSilhouette (in
  // tracker/hull, > 127 is silhouette) gives the same.
  cv::Mat distance_to_silhouette;
};

struct AxisPoint3d {
  Eigen::Vector3d p_in_world = Eigen::Vector3d::Zero();  // metres
  BodyPart part = BodyPart::kNone;                       // kHead, kTorso or kArm
  double diameter_m = 0;  // from the 2D diameters and depths, averaged over both views
  int camera_a = -1, camera_b = -1;  // views that triangulated it (first of a merged group)
  int merged = 1;                    // how many triangulations were averaged into it
  int support = 0;                   // views whose silhouette contains its projection
};

struct Axis3dOptions {
  // Skip an intersection where the epipolar line makes less than this angle
  // with the other image's 2D axis there (thesis 4.4.2's coplanar case), deg.
  double min_epipolar_angle_deg = 25;
  // Skip an intersection whose two viewing rays are within this of parallel or
  // antiparallel, deg.
  double min_ray_angle_deg = 15;
  // Axis points of one part within this distance in the other image (pixels,
  // undistorted) are joined into the axis polyline that epipolar lines cut.
  double link_px = 2.5;
  // Axis points thinner than this fraction of their part's median diameter
  // (in that view) are left out: the caps at a limb's ends.
  double min_diameter_fraction = 0.75;
  // A 3D point must project within this distance of the silhouette in every
  // view where it lands inside the image, pixels.
  double silhouette_tolerance_px = 1.5;
  // Triangulated points of one part closer than this are averaged (0: off), m.
  double merge_radius_m = 0.01;
  void Check() const;  // throws InputError naming the field
};

// Thesis 4.4.2: triangulates head, torso and arm axes across every pair of
// labelled views. Head and torso meet their own part; either image arm meets
// either image arm of the other view (left/right in an image depends on the
// viewpoint), and the silhouette test of the other views removes the wrong
// matches. 3D arm points carry BodyPart::kArm.
std::vector<AxisPoint3d> ReconstructAxis3d(const std::vector<AxisView>& views,
                                           const Axis3dOptions& options = {});

struct BodyAxesOptions {
  AxisPointOptions points;
  BodyPartOptions parts;
  Axis3dOptions axis3d;
  // Views whose optical axis points more steeply than this above or below the
  // horizontal (an overhead camera) get no body parts: thesis 3.3's rules need
  // an upright person; they still check 3D points against their silhouette.
  double max_view_elevation_deg = 60;
  void Check() const;  // throws InputError naming the field
};

// One camera's 2D stages: its axis graph (3.2) and, unless the camera looks
// more steeply than options.max_view_elevation_deg, its body parts (3.3).
// `silhouette` is CV_8UC1 of the camera's size (not checked here); the view
// keeps it. distance_to_silhouette is left to the caller.
AxisView MakeAxisView(const Camera& camera, const cv::Mat& silhouette, const BodyAxesOptions& options);

// The whole chain for one frame: 2D axis points (3.2), body parts (3.3) and 3D
// axis points (4.4.2). `silhouettes[i]` is CV_8UC1 of `cameras[i]`'s size.
// `views_out`, when given, receives each camera's 2D axis graph and part labels.
// `distances`, when given, holds each camera's AxisView::distance_to_silhouette.
// The cameras' 2D stages run in parallel. Throws std::invalid_argument for
// mismatched inputs.
std::vector<AxisPoint3d> ReconstructBodyAxes(const std::vector<Camera>& cameras,
                                             const std::vector<cv::Mat>& silhouettes,
                                             const BodyAxesOptions& options = {},
                                             std::vector<AxisView>* views_out = nullptr,
                                             const std::vector<cv::Mat>* distances = nullptr);

}  // namespace irbench
