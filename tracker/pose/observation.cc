#include "tracker/pose/observation.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "common/error.h"

namespace irbench {

void ObservationOptions::Check() const {
  if (!(scale > 0 && scale <= 1)) throw InputError("", "observation.scale", "must be in (0, 1]");
  if (!(sharpness > 0)) throw InputError("", "observation.sharpness", "must be positive");
}

void MakeUndistortMaps(const Camera& camera, cv::Mat* map1, cv::Mat* map2) {
  cv::Mat K;
  cv::eigen2cv(camera.K(), K);
  const cv::Mat dist(1, 5, CV_64F, const_cast<double*>(camera.dist.data()));
  cv::initUndistortRectifyMap(K, dist, cv::noArray(), K, cv::Size(camera.width, camera.height), CV_32FC1, *map1,
                              *map2);
}

SilhouetteView::SilhouetteView(const Camera& camera, const cv::Mat& silhouette, const cv::Mat& map1,
                               const cv::Mat& map2, double scale)
    : scale_(scale) {
  cv::remap(silhouette, ideal_, map1, map2, cv::INTER_NEAREST, cv::BORDER_CONSTANT, 0);
  (void)camera;
  if (scale == 1.0) {
    level_ = ideal_ > 0;
  } else {
    cv::Mat small;
    cv::resize(ideal_ > 0, small, cv::Size(), scale, scale, cv::INTER_AREA);
    level_ = small >= 128;
  }
  row_prefix_.create(level_.rows, level_.cols + 1, CV_32S);
  area_ = 0;
  for (int y = 0; y < level_.rows; ++y) {
    const uint8_t* in = level_.ptr<uint8_t>(y);
    int* out = row_prefix_.ptr<int>(y);
    out[0] = 0;
    for (int x = 0; x < level_.cols; ++x) out[x + 1] = out[x] + (in[x] ? 1 : 0);
    area_ += out[level_.cols];
  }
}

double SilhouetteView::OverlapRatio(const std::vector<ImageEllipse>& ellipses) const {
  const int rows = level_.rows, cols = level_.cols;
  constexpr int kMaxSpans = 16;
  struct Row {
    std::array<std::pair<int, int>, kMaxSpans> spans;
    int count = 0;
  };
  // At most a few hundred rows: a stack-free scratch buffer per thread.
  thread_local std::vector<Row> scratch;
  scratch.assign(rows, Row{});
  int first_row = rows, last_row = -1;
  for (const ImageEllipse& full : ellipses) {
    const ImageEllipse e = scale_ == 1.0 ? full : full.Scaled(scale_);
    const Eigen::Matrix2d& m = e.shape;
    const double det = m.determinant();
    if (!(det > 0)) continue;
    const double half_height = std::sqrt(m(0, 0) / det);  // sqrt((M^-1)_yy)
    const int y0 = std::max(0, static_cast<int>(std::ceil(e.center.y() - half_height)));
    const int y1 = std::min(rows - 1, static_cast<int>(std::floor(e.center.y() + half_height)));
    for (int y = y0; y <= y1; ++y) {
      const double dy = y - e.center.y();
      const double b = m(0, 1) * dy;
      const double disc = b * b - m(0, 0) * (m(1, 1) * dy * dy - 1.0);
      if (disc < 0) continue;
      const double root = std::sqrt(disc);
      const int x0 = std::max(0, static_cast<int>(std::ceil(e.center.x() + (-b - root) / m(0, 0))));
      const int x1 = std::min(cols - 1, static_cast<int>(std::floor(e.center.x() + (-b + root) / m(0, 0))));
      if (x1 < x0) continue;
      Row& row = scratch[y];
      if (row.count < kMaxSpans) row.spans[row.count++] = {x0, x1};
      first_row = std::min(first_row, y);
      last_row = std::max(last_row, y);
    }
  }
  long model_area = 0, overlap = 0;
  for (int y = first_row; y <= last_row; ++y) {
    Row& row = scratch[y];
    if (row.count == 0) continue;
    std::sort(row.spans.begin(), row.spans.begin() + row.count);
    const int* prefix = row_prefix_.ptr<int>(y);
    int start = row.spans[0].first, end = row.spans[0].second;
    auto flush = [&] {
      model_area += end - start + 1;
      overlap += prefix[end + 1] - prefix[start];
    };
    for (int i = 1; i < row.count; ++i) {
      if (row.spans[i].first <= end + 1) {
        end = std::max(end, row.spans[i].second);
      } else {
        flush();
        start = row.spans[i].first;
        end = row.spans[i].second;
      }
    }
    flush();
  }
  const long union_area = model_area + area_ - overlap;
  return union_area > 0 ? static_cast<double>(overlap) / union_area : 0.0;
}

std::vector<std::vector<Eigen::Vector2d>> OutlinePolygons(const cv::Mat& silhouette, double tolerance_px,
                                                          double min_area_px) {
  std::vector<std::vector<cv::Point>> contours;
  cv::findContours(silhouette > 0, contours, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_NONE);
  std::vector<std::vector<Eigen::Vector2d>> out;
  for (const auto& contour : contours) {
    if (cv::contourArea(contour) < min_area_px) continue;
    std::vector<cv::Point> poly;
    cv::approxPolyDP(contour, poly, tolerance_px, true);
    std::vector<Eigen::Vector2d> p;
    for (const cv::Point& q : poly) p.emplace_back(q.x, q.y);
    out.push_back(std::move(p));
  }
  return out;
}

cv::Mat RasteriseEllipses(const std::vector<ImageEllipse>& ellipses, cv::Size size) {
  cv::Mat out(size, CV_8UC1, cv::Scalar(0));
  for (int y = 0; y < size.height; ++y) {
    uint8_t* row = out.ptr<uint8_t>(y);
    for (int x = 0; x < size.width; ++x) {
      for (const ImageEllipse& e : ellipses) {
        const Eigen::Vector2d d = Eigen::Vector2d(x, y) - e.center;
        if (d.dot(e.shape * d) <= 1.0) {
          row[x] = 255;
          break;
        }
      }
    }
  }
  return out;
}

}  // namespace irbench
