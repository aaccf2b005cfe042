#pragma once
// The tracker's front end per frame-set (thesis ch. 3-4): for every camera, the
// silhouette from its background model, cleaned of shadows; the 2D axis points
// and body parts; across cameras, the 3D axis points. Trained from the
// sequence's empty-stage frames only.

#include <memory>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "tracker/axis/axis3d.h"
#include "tracker/frontend/camera_health.h"
#include "tracker/hull/polygon.h"
#include "tracker/hull/polyhedral_hull.h"
#include "tracker/hull/voxel_hull.h"
#include "tracker/io/sequence_input.h"
#include "tracker/silhouette/background_model.h"
#include "tracker/silhouette/shadow_removal.h"

namespace irbench {

struct FrontEndOptions {
  BackgroundOptions background;
  ShadowOptions shadow;
  bool remove_shadows = true;
  BodyAxesOptions axes;  // 2D axis points, body parts, 3D axis points
  bool find_axes = true;
  PolygonOptions polygons;  // silhouette outlines, 20-30 edges (thesis 3.1, 4.1)
  VoxelGridOptions voxels;  // voxel hull (thesis 4.2)
  bool carve_voxels = true;
  // When the hull of all views holds no person, place the body from the
  // hull of all views but one: the camera whose silhouette covers least of
  // what the other cameras' hull projects into it, when that share is below
  // `placement_max_coverage` (a view that lost most of the body: an
  // overhead camera over a floor as grey as the clothing, under heavy
  // noise). With 4 or more cameras only; the voxels stay the full hull.
  // On theater4 a view that lost the legs covers 0.24-0.35 of the others'
  // hull, an intact one 0.59 or more (frontend_closed_loop_test).
  bool placement_drop_view = true;
  double placement_max_coverage = 0.5;
  PolyhedralHullOptions polyhedral;  // polyhedral hull (thesis 4.1)
  // Built on request (irbench track --ply): nothing downstream uses it yet and
  // it is the front end's most expensive stage.
  bool polyhedral_hull = false;
  // Which cameras a frame-set is tracked without (irbench track).
  CameraHealthOptions health;
  void Check() const;  // throws InputError naming the field
};

struct CameraFeatures {
  cv::Mat silhouette;      // CV_8UC1 255/0, shadows removed when asked
  cv::Mat before_shadows;  // the background model's mask
  double light_level = 0;
  int blobs_removed = 0;
  // Filled by the caller that watches the cameras (irbench track): the
  // frame's state and mean grey level.
  CameraHealth health = CameraHealth::kOk;
  double mean_level = 0;
};

// Where the person stands, from the voxel hull (thesis 6.1.2 places the body
// from its 3D shape): the floor point under the centroid of the occupied
// voxels below `legs_height_m` (legs and feet: the arms do not pull it), and
// the hull's top. nullopt when the hull holds less than `min_volume_m3`
// (an empty stage).
struct BodyPlacement {
  Eigen::Vector3d root = Eigen::Vector3d::Zero();  // z = 0
  double top_m = 0;
  double volume_m3 = 0;
  // -1: from the hull of all views; else the camera left out
  // (FrontEndOptions::placement_drop_view) and the share of the other views'
  // hull its silhouette covered.
  int dropped_view = -1;
  double dropped_view_coverage = 1;
};
std::optional<BodyPlacement> PlaceBody(const VoxelHull& hull, double legs_height_m = 0.5,
                                       double min_volume_m3 = 0.02);

// The placement from the hull of all cameras but one, for when one camera's
// silhouette lost the body (PlaceBody of the full hull found none): for each
// camera c with any silhouette, the hull of the others (c's image taken as
// all silhouette) and the share of that hull's voxel centres c's silhouette
// covers; the camera covering least, when below `max_coverage`. nullopt when
// no camera qualifies. `distances`: the silhouettes' DistanceToSilhouette
// when the caller has them (computed otherwise).
std::optional<BodyPlacement> PlaceBodyWithoutOneView(const VoxelCarver& carver, const std::vector<cv::Mat>& silhouettes,
                                                     double max_coverage,
                                                     const std::vector<cv::Mat>* distances = nullptr);

struct FrameFeatures {
  int frame = 0;
  std::vector<CameraFeatures> cameras;
  // Per camera: true for a camera left out of this frame-set (its frame
  // missing, black or frozen: camera_health.h). A left-out camera's
  // silhouette is empty and it constrains nothing: not the hull, the 3D axis
  // points or the pose likelihood. Empty: none left out.
  std::vector<bool> left_out;
  bool LeftOut(size_t c) const { return c < left_out.size() && left_out[c]; }
  int UsableCameras() const;
  // Per camera: the 2D axis graph and part labels (thesis 3.2-3.3).
  std::vector<AxisView> views;
  // 3D axis points by epipolar intersection (thesis 4.4.2).
  std::vector<AxisPoint3d> axis3d;
  std::vector<SilhouettePolygons> polygons;  // per camera
  std::optional<VoxelHull> voxels;
  std::optional<HullMesh> hull;  // the polyhedral hull (not watertight)
  std::optional<BodyPlacement> placement;  // nullopt: the stage looks empty
  // Wall time of each stage for all cameras. The per-camera stages run as
  // one task per camera; their share of that part's wall time is their share
  // of the time on the threads, so the stages add up to the front end's.
  double ms_silhouettes = 0;
  double ms_axes = 0;
  double ms_polygons = 0;
  double ms_voxels = 0;
  double ms_polyhedral = 0;
};

// 255 where `camera` sees one of `screens` (from the front), from the
// calibration and the surveyed screen geometry.
cv::Mat ScreenMask(const Camera& camera, const std::vector<ScreenSurface>& screens);

class FrontEnd {
 public:
  // Throws InputError when the sequence has no empty-stage frames.
  static FrontEnd Train(const SequenceInput& input, const FrontEndOptions& options);
  // `frames`: one 8-bit image per camera, in the input's camera order, of
  // the camera's size (std::invalid_argument otherwise). The per-camera
  // stages run in parallel over the cameras; the result does not depend on
  // the thread count. `left_out` (empty, or one flag per camera): cameras to
  // leave out of this frame-set; their frames may be empty Mats.
  FrameFeatures Process(int frame, const std::vector<cv::Mat>& frames,
                        const std::vector<bool>& left_out = {}) const;

  const FrontEndOptions& options() const { return options_; }
  // Per camera, what its empty-stage frames say for the camera health monitor.
  const std::vector<CameraReference>& camera_references() const { return camera_references_; }

 private:
  // Camera c's part of a frame-set it is left out of.
  void LeaveOut(int c, bool need_distances, FrameFeatures* out, std::vector<cv::Mat>* silhouettes,
                std::vector<cv::Mat>* distances, std::vector<AxisView>* views) const;

  FrontEndOptions options_;
  std::vector<BackgroundModel> background_;
  std::vector<ShadowRemover> shadows_;
  std::vector<Camera> cameras_;
  std::vector<CameraReference> camera_references_;
  std::shared_ptr<const VoxelCarver> carver_;  // its look-up table is built once per rig
};

}  // namespace irbench
