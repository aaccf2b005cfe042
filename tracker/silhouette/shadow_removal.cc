#include "tracker/silhouette/shadow_removal.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

namespace irbench {

void ShadowOptions::Check() const {
  if (!(blur_sigma >= 0)) throw std::invalid_argument("shadow blur_sigma: must be >= 0");
  if (!(canny_low > 0 && canny_high >= canny_low)) {
    throw std::invalid_argument("shadow canny thresholds: need 0 < low <= high");
  }
  if (!(background_edge_rate > 0 && background_edge_rate <= 1)) {
    throw std::invalid_argument("shadow background_edge_rate: must be in (0, 1]");
  }
  if (edge_dilate < 0 || edge_reach < 0) throw std::invalid_argument("shadow edge_dilate/edge_reach: must be >= 0");
  if (min_directions < 1 || min_directions > 4) throw std::invalid_argument("shadow min_directions: must be 1..4");
}

cv::Mat ShadowRemover::Edges(const cv::Mat& frame) const {
  cv::Mat smooth = frame, edges;
  if (options_.blur_sigma > 0) cv::GaussianBlur(frame, smooth, cv::Size(), options_.blur_sigma);
  cv::Canny(smooth, edges, options_.canny_low, options_.canny_high, 3, true);
  return edges;
}

std::optional<ShadowRemover> ShadowRemover::Train(const std::vector<cv::Mat>& background,
                                                  const ShadowOptions& options) {
  options.Check();
  if (background.empty()) return std::nullopt;
  ShadowRemover r;
  r.options_ = options;
  cv::Mat count = cv::Mat::zeros(background[0].size(), CV_32F);
  for (const cv::Mat& f : background) {
    if (f.size() != background[0].size() || f.type() != CV_8UC1) return std::nullopt;
    cv::Mat e;
    r.Edges(f).convertTo(e, CV_32F, 1.0 / 255);
    count += e;
  }
  cv::Mat rate = count / static_cast<double>(background.size());
  r.background_edges_ = rate > options.background_edge_rate;
  // Edges move by a pixel with noise: a background edge covers its neighbours.
  cv::dilate(r.background_edges_, r.background_edges_, cv::Mat());
  return r;
}

cv::Mat ShadowRemover::SegmentedEdges(const cv::Mat& frame, const cv::Mat& silhouette) const {
  return SegmentedEdges(frame, silhouette, background_edges_, frame.cols / 320.0);
}

cv::Mat ShadowRemover::SegmentedEdges(const cv::Mat& frame, const cv::Mat& silhouette,
                                      const cv::Mat& background_edges, double scale) const {
  cv::Mat edges = Edges(frame);
  edges.setTo(0, background_edges);
  const int dilate = static_cast<int>(std::lround(options_.edge_dilate * scale));
  if (dilate > 0) {
    cv::dilate(edges, edges,
               cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * dilate + 1, 2 * dilate + 1)));
  }
  // Only edges at or inside the silhouette's outline matter.
  cv::Mat near;
  const int reach = std::max(1, static_cast<int>(std::lround((options_.edge_reach + 1) * scale)));
  cv::dilate(silhouette, near, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(2 * reach + 1, 2 * reach + 1)));
  edges.setTo(0, near == 0);
  return edges;
}

cv::Mat ShadowRemover::Remove(const cv::Mat& frame, const cv::Mat& silhouette, const cv::Mat& darker) const {
  cv::Mat kept = cv::Mat::zeros(silhouette.size(), CV_8U);
  const cv::Rect box = cv::boundingRect(silhouette);
  if (box.empty()) return kept;
  // Work inside the silhouette's box, with room for the blur, the dilations
  // and the reach; the result is the same as on the whole image.
  const double scale = frame.cols / 320.0;
  const int margin = static_cast<int>(std::ceil((4 * options_.blur_sigma + options_.edge_dilate +
                                                 options_.edge_reach + 4) * scale));
  const cv::Rect roi = cv::Rect(box.x - margin, box.y - margin, box.width + 2 * margin, box.height + 2 * margin) &
                       cv::Rect(0, 0, frame.cols, frame.rows);
  const cv::Mat edges = SegmentedEdges(frame(roi), silhouette(roi), background_edges_(roi), scale);
  KeepEnclosed(silhouette(roi), edges, options_.min_directions,
               static_cast<int>(std::lround(options_.edge_reach * scale)))
      .copyTo(kept(roi));
  if (!darker.empty()) kept.setTo(255, silhouette & ~darker);
  return kept;
}

cv::Mat KeepEnclosed(const cv::Mat& silhouette, const cv::Mat& edges, int min_directions, int reach) {
  CV_Assert(silhouette.type() == CV_8UC1 && edges.type() == CV_8UC1 && silhouette.size() == edges.size());
  const int w = silhouette.cols, h = silhouette.rows;
  cv::Mat votes = cv::Mat::zeros(silhouette.size(), CV_8U);
  const int dirs[4][2] = {{1, 0}, {0, 1}, {1, 1}, {1, -1}};
  std::vector<cv::Point> line;
  for (const auto& d : dirs) {
    const int dx = d[0], dy = d[1];
    // Start points: every pixel whose predecessor along (dx, dy) is outside.
    for (int y0 = 0; y0 < h; ++y0) {
      for (int x0 = 0; x0 < w; ++x0) {
        const int px = x0 - dx, py = y0 - dy;
        if (px >= 0 && px < w && py >= 0 && py < h) continue;
        line.clear();
        for (int x = x0, y = y0; x >= 0 && x < w && y >= 0 && y < h; x += dx, y += dy) line.push_back({x, y});
        // Runs of silhouette pixels along the line.
        for (size_t i = 0; i < line.size();) {
          if (!silhouette.at<uint8_t>(line[i])) {
            ++i;
            continue;
          }
          size_t j = i;
          while (j < line.size() && silhouette.at<uint8_t>(line[j])) ++j;
          // Run [i, j): first and last segmented edge, within `reach` outside
          // the run too (the outline's edge may sit on the background side).
          const long lo = std::max<long>(0, static_cast<long>(i) - reach);
          const long hi = std::min<long>(static_cast<long>(line.size()), static_cast<long>(j) + reach);
          long first = -1, last = -1;
          for (long k = lo; k < hi; ++k) {
            if (edges.at<uint8_t>(line[k])) {
              if (first < 0) first = k;
              last = k;
            }
          }
          if (first >= 0) {
            for (long k = std::max<long>(first, static_cast<long>(i)); k <= std::min<long>(last, static_cast<long>(j) - 1); ++k) {
              ++votes.at<uint8_t>(line[k]);
            }
          }
          i = j;
        }
      }
    }
  }
  cv::Mat out = cv::Mat::zeros(silhouette.size(), CV_8U);
  out.setTo(255, votes >= min_directions);
  out.setTo(0, silhouette == 0);
  return out;
}

}  // namespace irbench
