#include "tracker/axis/axis_points.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <array>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "common/error.h"

namespace irbench {
namespace {

// Scan lines of one direction over a width x height image: line k, position t
// along it, and the pixel (u, v) there. Lines k and k + 1 hold 4-neighbour
// pixels at equal t, so runs on adjacent lines overlap when their t ranges do.
struct ScanLines {
  ScanDirection direction;
  int width, height;

  int Count() const {
    switch (direction) {
      case ScanDirection::kHorizontal: return height;
      case ScanDirection::kVertical: return width;
      default: return width + height - 1;
    }
  }
  // Inclusive t range of line k.
  std::pair<int, int> Range(int k) const {
    switch (direction) {
      case ScanDirection::kHorizontal: return {0, width - 1};
      case ScanDirection::kVertical: return {0, height - 1};
      case ScanDirection::kDiagonalDown:  // u = k - (height - 1) + t, v = t
        return {std::max(0, height - 1 - k), std::min(height - 1, width - 1 - k + height - 1)};
      case ScanDirection::kDiagonalUp:  // u = t, v = k - t
        return {std::max(0, k - (height - 1)), std::min(width - 1, k)};
    }
    return {0, -1};
  }
  // Inclusive t range of line k's pixels inside `box` (empty: first > second).
  std::pair<int, int> RangeIn(int k, const cv::Rect& box) const {
    auto [lo, hi] = Range(k);
    const int x0 = box.x, x1 = box.x + box.width - 1, y0 = box.y, y1 = box.y + box.height - 1;
    auto clip = [&lo = lo, &hi = hi](int a, int b) {
      lo = std::max(lo, a);
      hi = std::min(hi, b);
    };
    switch (direction) {
      case ScanDirection::kHorizontal:
        if (k < y0 || k > y1) return {0, -1};
        clip(x0, x1);
        break;
      case ScanDirection::kVertical:
        if (k < x0 || k > x1) return {0, -1};
        clip(y0, y1);
        break;
      case ScanDirection::kDiagonalDown:
        clip(y0, y1);
        clip(x0 - k + height - 1, x1 - k + height - 1);
        break;
      case ScanDirection::kDiagonalUp:
        clip(x0, x1);
        clip(k - y1, k - y0);
        break;
    }
    return {lo, hi};
  }
  cv::Point Pixel(int k, int t) const {
    switch (direction) {
      case ScanDirection::kHorizontal: return {t, k};
      case ScanDirection::kVertical: return {k, t};
      case ScanDirection::kDiagonalDown: return {k - (height - 1) + t, t};
      case ScanDirection::kDiagonalUp: return {t, k - t};
    }
    return {0, 0};
  }
  Eigen::Vector2d PixelAt(int k, double t) const {
    const cv::Point p0 = Pixel(k, 0);
    return Eigen::Vector2d(p0.x, p0.y) + t * StepVector();
  }
  // Pixel offset per unit t (not normalised).
  Eigen::Vector2d StepVector() const {
    switch (direction) {
      case ScanDirection::kHorizontal: return {1, 0};
      case ScanDirection::kVertical: return {0, 1};
      case ScanDirection::kDiagonalDown: return {1, 1};
      case ScanDirection::kDiagonalUp: return {1, -1};
    }
    return {1, 0};
  }
};

}  // namespace

Eigen::Vector2d ScanStep(ScanDirection direction) {
  return ScanLines{direction, 1, 1}.StepVector().normalized();
}

void AxisPointOptions::Check() const {
  if (min_run_px < 1) throw InputError("", "AxisPointOptions.min_run_px", "must be >= 1");
  if (!(keep_slack >= 0 && keep_slack < 1)) throw InputError("", "AxisPointOptions.keep_slack", "must be in [0, 1)");
  if (axis_fit_hops < 1) throw InputError("", "AxisPointOptions.axis_fit_hops", "must be >= 1");
}

AxisGraph ExtractAxisPoints(const cv::Mat& silhouette, const AxisPointOptions& options) {
  options.Check();
  if (silhouette.empty() || silhouette.type() != CV_8UC1) {
    throw std::invalid_argument("ExtractAxisPoints: the silhouette must be a non-empty CV_8UC1 image");
  }
  AxisGraph graph;
  graph.width = silhouette.cols;
  graph.height = silhouette.rows;
  const int w = graph.width, h = graph.height;

  // Only the silhouette's box holds runs: each line is scanned across it.
  const cv::Rect box = cv::boundingRect(silhouette);
  // Run length (pixels, diagonals scaled) through every foreground pixel, per
  // direction; over the box (pixel p at p - box.tl()).
  std::array<cv::Mat1f, kScanDirectionCount> run_length;
  // Per direction and line: indices of its axis points in increasing t.
  std::array<std::vector<std::vector<int>>, kScanDirectionCount> by_line;
  for (int d = 0; d < kScanDirectionCount; ++d) {
    const ScanLines lines{ScanDirection(d), w, h};
    const double step_len = lines.StepVector().norm();
    run_length[d] = cv::Mat1f(box.height, box.width, 0.0f);
    by_line[d].resize(lines.Count());
    if (box.empty()) continue;
    for (int k = 0; k < lines.Count(); ++k) {
      const auto [t_begin, t_end] = lines.RangeIn(k, box);
      int t = t_begin;
      while (t <= t_end) {
        cv::Point p = lines.Pixel(k, t);
        if (!silhouette.at<uint8_t>(p)) {
          ++t;
          continue;
        }
        const int t0 = t;
        while (t <= t_end && silhouette.at<uint8_t>(lines.Pixel(k, t))) ++t;
        const int t1 = t - 1;
        const double length = (t1 - t0 + 1) * step_len;
        for (int s = t0; s <= t1; ++s) run_length[d](lines.Pixel(k, s) - box.tl()) = float(length);
        if (t1 - t0 + 1 < options.min_run_px) continue;
        AxisPoint2d point;
        point.px = lines.PixelAt(k, 0.5 * (t0 + t1));
        point.run_px = length;
        point.diameter_px = length;
        point.direction = ScanDirection(d);
        point.line = k;
        point.t0 = t0;
        point.t1 = t1;
        by_line[d][k].push_back(int(graph.points.size()));
        graph.points.push_back(std::move(point));
      }
    }
  }

  // Neighbours: runs on adjacent lines of one direction whose t ranges overlap.
  for (int d = 0; d < kScanDirectionCount; ++d) {
    for (size_t k = 0; k + 1 < by_line[d].size(); ++k) {
      const std::vector<int>& a = by_line[d][k];
      const std::vector<int>& b = by_line[d][k + 1];
      size_t i = 0, j = 0;
      while (i < a.size() && j < b.size()) {
        AxisPoint2d& pa = graph.points[a[i]];
        AxisPoint2d& pb = graph.points[b[j]];
        if (pa.t0 <= pb.t1 && pb.t0 <= pa.t1) {
          pa.neighbors.push_back(b[j]);
          pb.neighbors.push_back(a[i]);
        }
        if (pa.t1 < pb.t1) ++i; else ++j;
      }
    }
  }

  // Keep rule, local axis direction and perpendicular diameter.
  std::vector<int> hop(graph.points.size(), -1);
  std::vector<int> visited;
  for (size_t i = 0; i < graph.points.size(); ++i) {
    AxisPoint2d& point = graph.points[i];
    const int d = int(point.direction);
    const ScanLines lines{point.direction, w, h};
    const cv::Point mid = lines.Pixel(point.line, (point.t0 + point.t1) / 2);
    float shortest_other = std::numeric_limits<float>::infinity();
    for (int e = 0; e < kScanDirectionCount; ++e) {
      if (e != d) shortest_other = std::min(shortest_other, run_length[e](mid - box.tl()));
    }
    point.kept = point.run_px <= (1 + options.keep_slack) * shortest_other;

    // Breadth-first over the neighbour graph, up to axis_fit_hops.
    visited.assign(1, int(i));
    hop[i] = 0;
    for (size_t q = 0; q < visited.size(); ++q) {
      const int at = visited[q];
      if (hop[at] >= options.axis_fit_hops) continue;
      for (int n : graph.points[at].neighbors) {
        if (hop[n] >= 0) continue;
        hop[n] = hop[at] + 1;
        visited.push_back(n);
      }
    }
    if (visited.size() >= 3) {
      Eigen::Vector2d mean = Eigen::Vector2d::Zero();
      for (int v : visited) mean += graph.points[v].px;
      mean /= double(visited.size());
      Eigen::Matrix2d scatter = Eigen::Matrix2d::Zero();
      for (int v : visited) {
        const Eigen::Vector2d x = graph.points[v].px - mean;
        scatter += x * x.transpose();
      }
      const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> solver(scatter);
      point.axis_dir = solver.eigenvectors().col(1).normalized();
      if (point.kept) {
        const Eigen::Vector2d step = ScanStep(point.direction);
        point.diameter_px = point.run_px * std::abs(step.x() * point.axis_dir.y() - step.y() * point.axis_dir.x());
      }
    }
    for (int v : visited) hop[v] = -1;
  }
  return graph;
}

}  // namespace irbench
