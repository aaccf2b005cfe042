#pragma once
// A decoded video or capture frame as the tracker reads it: 8-bit grey.

#include <opencv2/core.hpp>

namespace irbench {

// Colour frames turned grey with ITU-R BT.601 weights (FFmpeg hands grey
// videos back as BGR with equal channels, which this keeps exactly); 16-bit
// frames scaled to 8 bits.
cv::Mat GreyFrame(const cv::Mat& decoded);

}  // namespace irbench
