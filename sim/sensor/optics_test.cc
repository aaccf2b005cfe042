#include "sim/sensor/optics.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

namespace irbench {
namespace {

Camera TestCamera() {
  Camera cam;
  cam.width = 160;
  cam.height = 120;
  cam.fx = cam.fy = 150;
  cam.cx = 79.5;
  cam.cy = 59.5;
  return cam;
}

TEST(OpticsTest, CircleOfConfusionFollowsTheThinLens) {
  OpticsParams p;
  p.f_number = 2.0;
  p.focal_length_mm = 4.0;
  p.focus_distance_m = 3.0;
  const Optics optics(p, TestCamera());
  EXPECT_NEAR(optics.CircleOfConfusionPx(3.0), 0.0, 1e-12);
  // c = fx * (f / N) * |z - S| / (z (S - f)).
  const double f = 0.004;
  EXPECT_NEAR(optics.CircleOfConfusionPx(1.5), 150 * (f / 2) * 1.5 / (1.5 * (3 - f)), 1e-12);
  EXPECT_GT(optics.CircleOfConfusionPx(1.0), optics.CircleOfConfusionPx(2.0));
}

TEST(OpticsTest, DefocusBlursOnlyOutOfFocusAndVignettingDarkensCorners) {
  OpticsParams p;
  p.f_number = 1.0;
  p.focal_length_mm = 25.0;
  p.focus_distance_m = 3.0;
  p.vignetting = 1.0;
  const Camera cam = TestCamera();
  const Optics optics(p, cam);
  // A vertical edge; left half in focus (3 m), right half near (0.8 m).
  cv::Mat radiance(cam.height, cam.width, CV_32FC1, cv::Scalar(0.0f));
  radiance(cv::Rect(0, 0, 40, cam.height)) = 1.0f;
  radiance(cv::Rect(80, 0, 40, cam.height)) = 1.0f;
  cv::Mat depth(cam.height, cam.width, CV_32FC1, cv::Scalar(3.0f));
  depth(cv::Rect(60, 0, 100, cam.height)) = 0.8f;
  const cv::Mat out = optics.Apply(radiance, depth);
  const cv::Mat vignette_only = Optics(OpticsParams{.vignetting = 1.0}, cam).Apply(radiance, depth);
  // In focus: the edge at x = 40 stays sharp (up to vignetting).
  EXPECT_NEAR(out.at<float>(60, 38) / vignette_only.at<float>(60, 38), 1.0, 1e-3);
  EXPECT_NEAR(out.at<float>(60, 41), 0.0, 1e-3);
  // Out of focus: the edge at x = 80 spreads over several pixels.
  EXPECT_GT(out.at<float>(60, 78), 0.05);
  EXPECT_LT(out.at<float>(60, 81), 0.95 * vignette_only.at<float>(60, 81));
  // cos^4 fall-off: the centre keeps its light, a corner loses it.
  const cv::Mat flat(cam.height, cam.width, CV_32FC1, cv::Scalar(1.0f));
  const cv::Mat v = Optics(OpticsParams{.vignetting = 1.0}, cam).Apply(flat, cv::Mat());
  EXPECT_NEAR(v.at<float>(60, 80), 1.0, 1e-3);
  const double tan2 = (std::pow(79.5 / 150, 2) + std::pow(59.5 / 150, 2));
  EXPECT_NEAR(v.at<float>(0, 0), 1.0 / std::pow(1 + tan2, 2), 1e-4);
}

}  // namespace
}  // namespace irbench
