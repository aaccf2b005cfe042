#include "sim/sensor/emva1288.h"

#include <cmath>

namespace irbench {
namespace {

cv::Mat AsDouble(const cv::Mat& m) {
  cv::Mat d;
  m.convertTo(d, CV_64F);
  return d;
}

double Mean(const cv::Mat& m) { return cv::mean(m)[0]; }

double Variance(const cv::Mat& m) {
  cv::Scalar mean, std;
  cv::meanStdDev(m, mean, std);
  return std[0] * std[0];
}

}  // namespace

PhotonTransfer MeasurePhotonTransfer(const SensorModel& sensor,
                                     const cv::Mat& bright,
                                     const cv::Mat& dark,
                                     const std::vector<double>& exposures_ms,
                                     uint64_t first_frame) {
  PhotonTransfer result;
  uint64_t frame = first_frame;
  double dark_var_at_shortest = 0, shortest_ms = 0;
  for (double exposure_ms : exposures_ms) {
    const cv::Mat a = AsDouble(sensor.Expose(bright, exposure_ms, frame++));
    const cv::Mat b = AsDouble(sensor.Expose(bright, exposure_ms, frame++));
    const cv::Mat da = AsDouble(sensor.Expose(dark, exposure_ms, frame++));
    const cv::Mat db = AsDouble(sensor.Expose(dark, exposure_ms, frame++));
    // Pair differences remove the fixed patterns: var(a - b) / 2 is temporal.
    const double var_dark = 0.5 * Variance(da - db);
    result.mean_dn.push_back(0.5 * (Mean(a) + Mean(b)) - 0.5 * (Mean(da) + Mean(db)));
    result.variance_dn2.push_back(0.5 * Variance(a - b) - var_dark);
    if (shortest_ms == 0 || exposure_ms < shortest_ms) {
      shortest_ms = exposure_ms;
      dark_var_at_shortest = var_dark;
    }
  }
  double sxy = 0, sxx = 0;
  for (size_t i = 0; i < result.mean_dn.size(); ++i) {
    sxy += result.mean_dn[i] * result.variance_dn2[i];
    sxx += result.mean_dn[i] * result.mean_dn[i];
  }
  result.gain_dn_per_e = sxy / sxx;
  result.dark_noise_e = std::sqrt(dark_var_at_shortest - 1.0 / 12) / result.gain_dn_per_e;
  result.frames_used = frame - first_frame;
  return result;
}

}  // namespace irbench
