#pragma once
// Lens effects on the radiance image before the sensor: defocus blur that
// grows with the distance from the focus plane (thin lens), vignetting, and
// glare around bright regions. Motion blur over the exposure is the render
// job's (it renders sub-frame poses and averages them).

#include <opencv2/core.hpp>

#include "geometry/camera.h"

namespace irbench {

struct OpticsParams {
  double f_number = 0.0;            // 0: pinhole, no defocus
  double focal_length_mm = 4.0;     // with fx, gives the aperture's size in pixels
  double focus_distance_m = 3.5;
  double vignetting = 0.0;          // 0 none .. 1 full cos^4 fall-off
  double glare_gain = 0.0;          // fraction of the light above the threshold spread around
  double glare_threshold = 0.8;     // relative radiance
  double glare_sigma_px = 6.0;
  int motion_blur_samples = 1;      // sub-frame renders averaged over the exposure

  bool Active() const { return f_number > 0 || vignetting > 0 || glare_gain > 0; }
};

class Optics {
 public:
  Optics(const OpticsParams& params, const Camera& camera);

  // Circle-of-confusion diameter in pixels of a point at camera depth z (m).
  double CircleOfConfusionPx(double z) const;
  // radiance: CV_32FC1; depth: CV_32FC1 camera z in metres (needed when
  // f_number > 0). Returns the radiance the sensor sees.
  cv::Mat Apply(const cv::Mat& radiance, const cv::Mat& depth) const;

 private:
  OpticsParams params_;
  double fx_;
  cv::Mat vignette_;  // CV_32FC1 gain per pixel
};

}  // namespace irbench
