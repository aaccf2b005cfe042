#include "tracker/hull/polygon.h"

#include <algorithm>
#include <opencv2/imgproc.hpp>

#include "common/error.h"

namespace irbench {
namespace {

struct RawContours {
  std::vector<std::vector<cv::Point>> contours;
  std::vector<cv::Vec4i> hierarchy;
  std::vector<int> kept;  // indices of contours that survive the area limits
  int largest_blob = -1;  // contour index of the largest outer contour
};

std::vector<Eigen::Vector2d> Approximate(const std::vector<cv::Point>& contour, double epsilon) {
  std::vector<cv::Point> approx;
  cv::approxPolyDP(contour, approx, epsilon, /*closed=*/true);
  std::vector<Eigen::Vector2d> out;
  out.reserve(approx.size());
  for (const cv::Point& p : approx) out.emplace_back(p.x, p.y);
  return out;
}

// Edges of the largest blob and its holes at tolerance `epsilon`.
int LargestBlobEdges(const RawContours& raw, double epsilon) {
  int edges = 0;
  for (int i : raw.kept) {
    const bool mine = i == raw.largest_blob || raw.hierarchy[i][3] == raw.largest_blob;
    if (mine) edges += static_cast<int>(Approximate(raw.contours[i], epsilon).size());
  }
  return edges;
}

// Moves every edge `d` pixels away from the silhouette (the silhouette lies
// left of travel on an outer loop of positive signed area, right on a hole).
void Offset(std::vector<Eigen::Vector2d>& loop, double d, bool hole) {
  const size_t n = loop.size();
  if (d == 0 || n < 3) return;
  // Outward normal of edge i (from vertex i to i + 1).
  const double sign = (SignedArea(loop) > 0 ? 1.0 : -1.0) * (hole ? -1.0 : 1.0);
  std::vector<Eigen::Vector2d> normal(n);
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector2d e = (loop[(i + 1) % n] - loop[i]).normalized();
    normal[i] = -sign * Eigen::Vector2d(-e.y(), e.x());
  }
  std::vector<Eigen::Vector2d> out(n);
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector2d& n0 = normal[(i + n - 1) % n];
    const Eigen::Vector2d& n1 = normal[i];
    const double c = 1 + n0.dot(n1);
    Eigen::Vector2d shift = c > 0.5 ? Eigen::Vector2d(d * (n0 + n1) / c)
                                    : Eigen::Vector2d(2 * d * (n0 + n1).normalized());
    if (!shift.allFinite()) shift = d * n1;
    out[i] = loop[i] + shift;
  }
  loop = std::move(out);
}

}  // namespace

void PolygonOptions::Check() const {
  if (epsilon_px < 0) throw InputError("", "polygons.epsilon_px", "must be >= 0 (0: adaptive)");
  if (min_edges < 3 || max_edges < min_edges)
    throw InputError("", "polygons.min_edges", "need 3 <= min_edges <= max_edges");
  if (min_epsilon_px <= 0 || max_epsilon_px < min_epsilon_px) {
    throw InputError("", "polygons.min_epsilon_px", "need 0 < min_epsilon_px <= max_epsilon_px");
  }
  if (min_blob_area_px < 0 || min_hole_area_px < 0)
    throw InputError("", "polygons.min_blob_area_px", "must be >= 0");
  if (outward_offset_px < 0 || outward_offset_px > 5)
    throw InputError("", "polygons.outward_offset_px", "must be in [0, 5]");
}

int SilhouettePolygons::EdgeCount() const {
  int n = 0;
  for (const PolygonLoop& loop : loops) n += static_cast<int>(loop.vertices.size());
  return n;
}

bool SilhouettePolygons::Contains(const Eigen::Vector2d& px) const {
  bool inside = false;
  for (const PolygonLoop& loop : loops) {
    const auto& v = loop.vertices;
    for (size_t i = 0, j = v.size() - 1; i < v.size(); j = i++) {
      if ((v[i].y() > px.y()) != (v[j].y() > px.y())) {
        const double x =
            v[j].x() + (px.y() - v[j].y()) * (v[i].x() - v[j].x()) / (v[i].y() - v[j].y());
        if (px.x() < x) inside = !inside;
      }
    }
  }
  return inside;
}

double SignedArea(const std::vector<Eigen::Vector2d>& loop) {
  double a = 0;
  for (size_t i = 0, j = loop.size() - 1; i < loop.size(); j = i++) {
    a += loop[j].x() * loop[i].y() - loop[i].x() * loop[j].y();
  }
  return 0.5 * a;
}

SilhouettePolygons ApproximateSilhouette(const cv::Mat& mask, const PolygonOptions& options) {
  options.Check();
  CV_Assert(mask.type() == CV_8UC1);
  SilhouettePolygons out;
  out.width = mask.cols;
  out.height = mask.rows;
  cv::Mat binary;
  cv::threshold(mask, binary, 127, 255, cv::THRESH_BINARY);
  RawContours raw;
  cv::findContours(binary, raw.contours, raw.hierarchy, cv::RETR_CCOMP, cv::CHAIN_APPROX_NONE);
  double largest_area = 0;
  // RETR_CCOMP: top-level contours are outer boundaries, their children holes.
  for (int i = 0; i < static_cast<int>(raw.contours.size()); ++i) {
    const bool hole = raw.hierarchy[i][3] >= 0;
    const double area = cv::contourArea(raw.contours[i]);
    if (hole) {
      if (!options.keep_holes || area < options.min_hole_area_px) continue;
      const int parent = raw.hierarchy[i][3];
      if (cv::contourArea(raw.contours[parent]) < options.min_blob_area_px) continue;
    } else {
      if (area < options.min_blob_area_px) continue;
      if (area > largest_area) largest_area = area, raw.largest_blob = i;
    }
    raw.kept.push_back(i);
  }
  if (raw.largest_blob < 0) return out;

  double epsilon = options.epsilon_px;
  if (epsilon == 0) {
    // Edge count falls (not strictly) as the tolerance grows: bisect for the
    // smallest tolerance that meets max_edges.
    double lo = options.min_epsilon_px, hi = options.max_epsilon_px;
    if (LargestBlobEdges(raw, lo) <= options.max_edges) {
      epsilon = lo;
    } else {
      for (int it = 0; it < 20; ++it) {
        const double mid = 0.5 * (lo + hi);
        (LargestBlobEdges(raw, mid) <= options.max_edges ? hi : lo) = mid;
      }
      epsilon = hi;
    }
  }
  out.epsilon_px = epsilon;

  std::vector<int> loop_of_contour(raw.contours.size(), -1);
  for (int i : raw.kept) {
    if (raw.hierarchy[i][3] >= 0) continue;
    PolygonLoop loop;
    loop.vertices = Approximate(raw.contours[i], epsilon);
    if (loop.vertices.size() < 3) continue;
    Offset(loop.vertices, options.outward_offset_px, false);
    loop.blob = static_cast<int>(out.loops.size());
    loop_of_contour[i] = loop.blob;
    out.loops.push_back(std::move(loop));
  }
  for (int i : raw.kept) {
    const int parent = raw.hierarchy[i][3];
    if (parent < 0 || loop_of_contour[parent] < 0) continue;
    PolygonLoop loop;
    loop.vertices = Approximate(raw.contours[i], epsilon);
    if (loop.vertices.size() < 3) continue;
    loop.hole = true;
    Offset(loop.vertices, options.outward_offset_px, true);
    loop.parent = loop_of_contour[parent];
    loop.blob = out.loops[loop.parent].blob;
    out.loops.push_back(std::move(loop));
  }
  return out;
}

cv::Mat RasterizePolygons(const SilhouettePolygons& polygons) {
  cv::Mat mask = cv::Mat::zeros(polygons.height, polygons.width, CV_8UC1);
  auto draw = [&](bool hole) {
    for (const PolygonLoop& loop : polygons.loops) {
      if (loop.hole != hole) continue;
      std::vector<cv::Point> pts;
      for (const auto& v : loop.vertices) pts.emplace_back(cvRound(v.x()), cvRound(v.y()));
      cv::fillPoly(mask, std::vector<std::vector<cv::Point>>{pts}, cv::Scalar(hole ? 0 : 255));
    }
  };
  draw(false);
  draw(true);
  return mask;
}

}  // namespace irbench
