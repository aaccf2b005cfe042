#pragma once
// Polygonal approximation of silhouette contours (thesis 4.1 step 1, Fig. 4.1;
// 6.2.1: "the silhouette can be approximated by 20-30 polygon edges"). Pixel
// coordinates follow OpenCV: the centre of the top-left pixel is (0, 0), u to
// the right, v down.

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <vector>

namespace irbench {

struct PolygonOptions {
  // Douglas-Peucker tolerance, pixels. 0: adaptive — the tolerance is searched
  // so that the largest blob's loops have between min_edges and max_edges edges.
  double epsilon_px = 0.0;
  int min_edges = 20;
  int max_edges = 30;
  // Bounds of the adaptive search, pixels.
  double min_epsilon_px = 0.5;
  double max_epsilon_px = 20.0;
  // Blobs (outer contours) and holes with a smaller area are dropped, pixels².
  double min_blob_area_px = 40.0;
  double min_hole_area_px = 40.0;
  bool keep_holes = true;
  // Contour pixels are pixel centres, half a pixel inside the silhouette's
  // outline: every polygon edge is moved this far outwards (away from the
  // silhouette, into holes), pixels. 0 keeps the vertices on pixel centres.
  double outward_offset_px = 0.5;

  void Check() const;  // throws InputError naming the field
};

// One closed loop; vertices in pixels, the last joins the first.
struct PolygonLoop {
  std::vector<Eigen::Vector2d> vertices;
  bool hole = false;  // a hole inside an outer loop (background)
  int parent = -1;    // for holes: index of the enclosing outer loop
  int blob = 0;       // index of the blob (outer loop) it belongs to
};

struct SilhouettePolygons {
  int width = 0, height = 0;  // of the mask, pixels
  std::vector<PolygonLoop> loops;
  double epsilon_px = 0.0;  // the tolerance used

  int EdgeCount() const;
  // Even-odd rule over all loops (holes subtract): is pixel position `px`
  // inside the polygonal silhouette?
  bool Contains(const Eigen::Vector2d& px) const;
};

// Finds outer contours and holes of a binary mask (CV_8UC1, > 127 is
// silhouette) and approximates each by a polygon whose vertices are contour
// pixel centres, then moves each edge outward_offset_px outwards (mitred
// corners, the miter capped at 2x the offset). Drops blobs and holes below the area limits. With
// epsilon_px == 0 the tolerance is the smallest one (bisection in
// [min_epsilon_px, max_epsilon_px]) for which the largest blob has at most
// max_edges edges; min_edges is then met unless the contour itself is simpler.
// An empty mask gives no loops.
SilhouettePolygons ApproximateSilhouette(const cv::Mat& mask, const PolygonOptions& options = {});

// Signed area by the shoelace formula, pixels² (positive when the loop runs
// counter-clockwise in a y-up frame, i.e. clockwise as seen in the image).
double SignedArea(const std::vector<Eigen::Vector2d>& loop);

// Rasterises the polygons back into a CV_8UC1 0/255 mask (for checks and
// display); holes are cut out.
cv::Mat RasterizePolygons(const SilhouettePolygons& polygons);

}  // namespace irbench
