#include "tracker/io/grey_frame.h"

#include <opencv2/imgproc.hpp>

namespace irbench {

cv::Mat GreyFrame(const cv::Mat& decoded) {
  cv::Mat grey;
  if (decoded.channels() == 3) {
    cv::cvtColor(decoded, grey, cv::COLOR_BGR2GRAY);
  } else if (decoded.channels() == 4) {
    cv::cvtColor(decoded, grey, cv::COLOR_BGRA2GRAY);
  } else {
    grey = decoded;
  }
  if (grey.depth() == CV_16U) grey.convertTo(grey, CV_8U, 1.0 / 257.0);
  return grey;
}

}  // namespace irbench
