#pragma once
// 2D body axis points (thesis 3.2): the silhouette is cut by arrays of scan
// lines in four directions; the midpoint of every run of foreground pixels is an
// axis point and the run's length its "diameter". Axis points of adjacent scan
// lines of one direction whose runs overlap are neighbours; the neighbour links
// form the body axis graph.
//
// Pixel coordinates follow OpenCV (and irbench::Camera): the centre of the
// top-left pixel is (0, 0), u to the right, v down.

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <vector>

namespace irbench {

enum class ScanDirection {
  kHorizontal = 0,    // along +u (rows)
  kVertical = 1,      // along +v (columns)
  kDiagonalDown = 2,  // along (+1, +1) / sqrt 2
  kDiagonalUp = 3,    // along (+1, -1) / sqrt 2
};
inline constexpr int kScanDirectionCount = 4;

// Unit step of a scan direction in pixels (u, v).
Eigen::Vector2d ScanStep(ScanDirection direction);

struct AxisPoint2d {
  Eigen::Vector2d px = Eigen::Vector2d::Zero();  // run midpoint, pixels
  // Run length along the scan line, pixels: the pixel count, times sqrt 2 for
  // the diagonals (thesis 3.2's "diameter").
  double run_px = 0;
  // For kept points, the run length projected perpendicular to the local axis
  // (run_px times |sin| of the angle between scan line and axis), pixels; else,
  // or when the local axis direction is unknown, run_px.
  double diameter_px = 0;
  // Unit local axis direction in the image, from the midpoints of neighbouring
  // axis points of the same direction; zero when too few neighbours.
  Eigen::Vector2d axis_dir = Eigen::Vector2d::Zero();
  ScanDirection direction = ScanDirection::kHorizontal;
  int line = 0;        // scan line index within its direction
  int t0 = 0, t1 = 0;  // first and last pixel of the run, as positions along the line
  // Thesis 3.2/3.3 selection: true when this direction cuts the silhouette most
  // nearly perpendicular to the local axis, i.e. no other direction has a
  // shorter run through the midpoint (within AxisPointOptions::keep_slack).
  bool kept = false;
  std::vector<int> neighbors;  // indices into AxisGraph::points, same direction only
};

struct AxisGraph {
  int width = 0, height = 0;  // of the silhouette, pixels
  std::vector<AxisPoint2d> points;
};

struct AxisPointOptions {
  int min_run_px = 2;  // shorter runs (pixel count) are noise and give no axis point
  // A point is kept when its run_px <= (1 + keep_slack) times the shortest run
  // of the other directions through its midpoint pixel.
  double keep_slack = 0.08;
  // Neighbour hops on each side used to estimate the local axis direction.
  int axis_fit_hops = 3;
  void Check() const;  // throws InputError naming the field
};

// Thesis 3.2: scans `silhouette` (CV_8UC1, foreground > 0) with horizontal,
// vertical and both diagonal scan lines, one line per pixel row/column/diagonal,
// and returns every run's axis point with the neighbour graph. Throws
// std::invalid_argument for an empty or non-CV_8UC1 image.
AxisGraph ExtractAxisPoints(const cv::Mat& silhouette, const AxisPointOptions& options = {});

}  // namespace irbench
