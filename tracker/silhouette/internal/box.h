#pragma once
// Helpers private to tracker/silhouette.

#include <opencv2/core.hpp>

namespace irbench::silhouette_internal {

// `box` grown by `margin` pixels on every side, within an image of `size`:
// the region an operation reading that far about `box` needs.
inline cv::Rect GrownWithin(const cv::Rect& box, int margin, const cv::Size& size) {
  return cv::Rect(box.x - margin, box.y - margin, box.width + 2 * margin, box.height + 2 * margin) &
         cv::Rect(cv::Point(0, 0), size);
}

}  // namespace irbench::silhouette_internal
