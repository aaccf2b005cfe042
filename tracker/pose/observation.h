#pragma once
// The particle filter's observation (thesis 6.3.1, Eq. 6.17): project the
// model into every camera and compare the projected area with the silhouette.
// Per camera the score is the overlap ratio |P ∩ S| / |P ∪ S| (overlap
// rewarded, both kinds of non-overlap penalised); cameras multiply.
//
// Speed (issue 7, item 8): the silhouettes are undistorted once per frame to
// the cameras' ideal pinhole (so model outlines stay exact ellipses),
// downsampled to a pyramid level, and kept as per-row prefix sums. A model's
// projection is then rasterised exactly, row by row, as the union of its
// ellipses' spans, and each span's overlap with the silhouette costs two
// look-ups. Nothing is drawn into an image.

#include <opencv2/core.hpp>
#include <vector>

#include "geometry/camera.h"
#include "tracker/body_model/body_model.h"
#include "tracker/body_model/ellipse_projection.h"

namespace irbench {

struct ObservationOptions {
  // Pyramid scale at which areas are compared (1: full resolution, 0.5: half).
  double scale = 0.5;
  // Log-likelihood = sharpness * sum over cameras of log(overlap ratio).
  double sharpness = 30.0;
  void Check() const;  // throws InputError naming the field
};

// One camera's ideal-pinhole silhouette, ready for overlap queries.
class SilhouetteView {
 public:
  SilhouetteView() = default;
  // `camera` with its distortion; `undistort_map_*` from MakeUndistortMaps.
  SilhouetteView(const Camera& camera, const cv::Mat& silhouette, const cv::Mat& map1, const cv::Mat& map2,
                 double scale);

  const cv::Mat& ideal_silhouette() const { return ideal_; }  // full resolution, undistorted
  const cv::Mat& level() const { return level_; }              // at `scale`
  int area() const { return area_; }                            // at `scale`
  double scale() const { return scale_; }

  // |P ∩ S| / |P ∪ S| for the union P of `ellipses` (full-resolution ideal
  // pixels); 0 when both are empty.
  double OverlapRatio(const std::vector<ImageEllipse>& ellipses) const;

 private:
  cv::Mat ideal_, level_;
  cv::Mat row_prefix_;  // CV_32S, rows x (cols + 1)
  int area_ = 0;
  double scale_ = 1.0;
};

// Maps for cv::remap from the camera's distorted image to its ideal pinhole
// with the same K.
void MakeUndistortMaps(const Camera& camera, cv::Mat* map1, cv::Mat* map2);

// The outer outlines of a silhouette as closed polygons (thesis 6.2.4 fits to
// polygons rather than every contour pixel): contours of at least
// `min_area_px`, simplified to within `tolerance_px`.
std::vector<std::vector<Eigen::Vector2d>> OutlinePolygons(const cv::Mat& silhouette, double tolerance_px = 1.5,
                                                          double min_area_px = 20);

// Rasterises the union of `ellipses` (pixel centres inside), for tests and
// overlays: 255 inside, 0 outside.
cv::Mat RasteriseEllipses(const std::vector<ImageEllipse>& ellipses, cv::Size size);

}  // namespace irbench
