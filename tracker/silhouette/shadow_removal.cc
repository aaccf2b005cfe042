#include "tracker/silhouette/shadow_removal.h"

#include "tracker/silhouette/internal/box.h"
#include "common/error.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

namespace irbench {

void ShadowOptions::Check() const {
  if (!(blur_sigma >= 0)) throw InputError("", "shadow.blur_sigma", "must be >= 0");
  if (!(canny_low > 0 && canny_high >= canny_low)) {
    throw InputError("", "shadow.canny_thresholds", "need 0 < low <= high");
  }
  if (!(background_edge_rate > 0 && background_edge_rate <= 1)) {
    throw InputError("", "shadow.background_edge_rate", "must be in (0, 1]");
  }
  if (edge_dilate < 0 || edge_reach < 0) throw InputError("", "shadow.edge_dilate/edge_reach", "must be >= 0");
  if (min_directions < 1 || min_directions > 4) throw InputError("", "shadow.min_directions", "must be 1..4");
}

cv::Mat ShadowRemover::Edges(const cv::Mat& frame) const {
  // A blur into a header of `frame` itself would write over the caller's image.
  cv::Mat smooth, edges;
  if (options_.blur_sigma > 0) {
    cv::GaussianBlur(frame, smooth, cv::Size(), options_.blur_sigma);
  } else {
    smooth = frame;
  }
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
  const cv::Rect roi = silhouette_internal::GrownWithin(box, margin, frame.size());
  const cv::Mat edges = SegmentedEdges(frame(roi), silhouette(roi), background_edges_(roi), scale);
  KeepEnclosed(silhouette(roi), edges, options_.min_directions,
               static_cast<int>(std::lround(options_.edge_reach * scale)))
      .copyTo(kept(roi));
  // (The silhouette lies within the box: the rest of the image is left alone.)
  if (!darker.empty()) kept(roi).setTo(255, silhouette(roi) & ~darker(roi));
  return kept;
}

cv::Mat KeepEnclosed(const cv::Mat& silhouette, const cv::Mat& edges, int min_directions, int reach) {
  CV_Assert(silhouette.type() == CV_8UC1 && edges.type() == CV_8UC1 && silhouette.size() == edges.size());
  const int w = silhouette.cols, h = silhouette.rows;
  cv::Mat votes = cv::Mat::zeros(silhouette.size(), CV_8U);
  const int dirs[4][2] = {{1, 0}, {0, 1}, {1, 1}, {1, -1}};
  // Every pixel lies on one line per direction; a pixel of a silhouette run
  // gets a vote from the direction when edges enclose it along the line.
  // One scan line: from (x0, y0) along (dx, dy) to the image's border.
  auto scan = [&](int x0, int y0, int dx, int dy) {
    int n = dx == 0 ? h - y0 : w - x0;
    if (dy > 0) n = std::min(n, h - y0);
    if (dy < 0) n = std::min(n, y0 + 1);
    const uint8_t* sil = silhouette.ptr<uint8_t>(y0) + x0;
    const uint8_t* edge = edges.ptr<uint8_t>(y0) + x0;
    uint8_t* vote = votes.ptr<uint8_t>(y0) + x0;
    const ptrdiff_t sil_step = dy * static_cast<ptrdiff_t>(silhouette.step) + dx;
    const ptrdiff_t edge_step = dy * static_cast<ptrdiff_t>(edges.step) + dx;
    const ptrdiff_t vote_step = dy * static_cast<ptrdiff_t>(votes.step) + dx;
    // Runs of silhouette pixels along the line.
    for (int i = 0; i < n;) {
      if (!sil[i * sil_step]) {
        ++i;
        continue;
      }
      int j = i;
      while (j < n && sil[j * sil_step]) ++j;
      // Run [i, j): first and last segmented edge, within `reach` outside
      // the run too (the outline's edge may sit on the background side).
      const int lo = std::max(0, i - reach), hi = std::min(n, j + reach);
      int first = -1, last = -1;
      for (int k = lo; k < hi; ++k) {
        if (edge[k * edge_step]) {
          if (first < 0) first = k;
          last = k;
        }
      }
      if (first >= 0) {
        for (int k = std::max(first, i); k <= std::min(last, j - 1); ++k) ++vote[k * vote_step];
      }
      i = j;
    }
  };
  for (const auto& d : dirs) {
    const int dx = d[0], dy = d[1];
    // Start points: the pixels whose predecessor along (dx, dy) is outside:
    // the left column when dx = 1, and the first row (dy = 1) or the last
    // (dy = -1).
    if (dx == 1) {
      for (int y0 = 0; y0 < h; ++y0) scan(0, y0, dx, dy);
    }
    if (dy != 0) {
      for (int x0 = dx; x0 < w; ++x0) scan(x0, dy > 0 ? 0 : h - 1, dx, dy);
    }
  }
  cv::Mat out(silhouette.size(), CV_8U);
  for (int y = 0; y < h; ++y) {
    const uint8_t* vp = votes.ptr<uint8_t>(y);
    const uint8_t* sp = silhouette.ptr<uint8_t>(y);
    uint8_t* op = out.ptr<uint8_t>(y);
    for (int x = 0; x < w; ++x) op[x] = sp[x] && vp[x] >= min_directions ? 255 : 0;
  }
  return out;
}

}  // namespace irbench
