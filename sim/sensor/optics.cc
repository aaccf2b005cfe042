#include "sim/sensor/optics.h"

#include <cmath>
#include <opencv2/imgproc.hpp>

namespace irbench {

Optics::Optics(const OpticsParams& params, const Camera& camera) : params_(params), fx_(camera.fx) {
  if (params.vignetting > 0) {
    // Natural vignetting: cos^4 of the angle between the pixel's ray and the axis.
    vignette_.create(camera.height, camera.width, CV_32FC1);
    for (int v = 0; v < camera.height; ++v) {
      for (int u = 0; u < camera.width; ++u) {
        const auto x = camera.UndistortPixel(Eigen::Vector2d(u, v));
        const double cos2 = x ? 1.0 / (1.0 + x->squaredNorm()) : 1.0;
        vignette_.at<float>(v, u) =
            static_cast<float>(1.0 - params.vignetting * (1.0 - cos2 * cos2));
      }
    }
  }
}

double Optics::CircleOfConfusionPx(double z) const {
  if (params_.f_number <= 0 || z <= 0) return 0.0;
  // Thin lens: c = A f |z - S| / (z (S - f)), A = f / N; in pixels via fx = f / pitch.
  const double f = params_.focal_length_mm / 1000.0;
  const double s = params_.focus_distance_m;
  return fx_ * (f / params_.f_number) * std::abs(z - s) / (z * (s - f));
}

cv::Mat Optics::Apply(const cv::Mat& radiance, const cv::Mat& depth) const {
  cv::Mat out = radiance;
  if (params_.f_number > 0 && !depth.empty()) {
    // Blur levels sigma = 0, 0.5, 1, 2, 4, 8 px; each pixel blends the two
    // levels around its own sigma (a Gaussian of about CoC / 2.5).
    const std::vector<double> sigmas = {0.0, 0.5, 1.0, 2.0, 4.0, 8.0};
    std::vector<cv::Mat> levels = {radiance};
    for (size_t i = 1; i < sigmas.size(); ++i) {
      cv::Mat blurred;
      cv::GaussianBlur(radiance, blurred, cv::Size(0, 0), sigmas[i], sigmas[i], cv::BORDER_REFLECT);
      levels.push_back(blurred);
    }
    out = cv::Mat(radiance.size(), CV_32FC1);
    for (int y = 0; y < radiance.rows; ++y) {
      for (int x = 0; x < radiance.cols; ++x) {
        const double sigma = std::min(CircleOfConfusionPx(depth.at<float>(y, x)) / 2.5, sigmas.back());
        size_t i = 0;
        while (i + 2 < sigmas.size() && sigmas[i + 1] < sigma) ++i;
        const double w = std::clamp((sigma - sigmas[i]) / (sigmas[i + 1] - sigmas[i]), 0.0, 1.0);
        out.at<float>(y, x) = static_cast<float>((1 - w) * levels[i].at<float>(y, x) +
                                                 w * levels[i + 1].at<float>(y, x));
      }
    }
  }
  if (!vignette_.empty()) out = out.mul(vignette_);
  if (params_.glare_gain > 0) {
    cv::Mat bright = cv::max(out - params_.glare_threshold, 0.0);
    cv::GaussianBlur(bright, bright, cv::Size(0, 0), params_.glare_sigma_px);
    out = out + params_.glare_gain * bright;
  }
  return out;
}

}  // namespace irbench
