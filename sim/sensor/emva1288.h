#pragma once
// The EMVA 1288 temporal measurement (photon transfer), usable on any
// SensorModel: it is how the sensor's configuration is checked against the
// frames it produces.

#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

#include "sim/sensor/sensor_model.h"

namespace irbench {

struct PhotonTransfer {
  std::vector<double> mean_dn;       // dark-corrected mean signal per exposure
  std::vector<double> variance_dn2;  // dark-corrected temporal variance per exposure
  double gain_dn_per_e = 0;          // K: slope of variance over mean (least squares through 0)
  // sigma_d = sqrt(dark variance - 1/12) / K at the shortest exposure, which
  // includes that exposure's dark-current shot noise.
  double dark_noise_e = 0;
  uint64_t frames_used = 0;          // frame indices first_frame .. first_frame + frames_used - 1
};

// Exposes a pair of `bright` and a pair of `dark` radiance images (CV_32FC1) at
// every exposure, with frame indices counting up from `first_frame`.
PhotonTransfer MeasurePhotonTransfer(const SensorModel& sensor,
                                     const cv::Mat& bright,
                                     const cv::Mat& dark,
                                     const std::vector<double>& exposures_ms,
                                     uint64_t first_frame);

}  // namespace irbench
