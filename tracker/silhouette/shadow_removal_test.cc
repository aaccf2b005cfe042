#include "tracker/silhouette/shadow_removal.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>
#include <random>

namespace irbench {
namespace {

TEST(KeepEnclosedTest, KeepsWhatEdgesEncloseOnEnoughScanLines) {
  cv::Mat sil = cv::Mat::zeros(100, 100, CV_8U);
  cv::rectangle(sil, cv::Rect(20, 20, 40, 50), 255, cv::FILLED);
  cv::Mat outline = cv::Mat::zeros(100, 100, CV_8U);
  cv::rectangle(outline, cv::Rect(20, 20, 40, 50), 255, 1);
  // Edges all around: everything is enclosed in all four directions.
  EXPECT_EQ(cv::countNonZero(KeepEnclosed(sil, outline, 4, 0)), 40 * 50);
  // Only the left and right sides: horizontal and both diagonals enclose
  // (three directions), vertical lines meet no edge.
  cv::Mat sides = cv::Mat::zeros(100, 100, CV_8U);
  cv::line(sides, {20, 20}, {20, 69}, 255);
  cv::line(sides, {59, 20}, {59, 69}, 255);
  EXPECT_EQ(cv::countNonZero(KeepEnclosed(sil, sides, 1, 0)), 40 * 50);
  // With all four required, only the edge columns themselves stay.
  EXPECT_EQ(cv::countNonZero(KeepEnclosed(sil, sides, 4, 0)), 2 * 50);
  // One side only: nothing but the edge pixels themselves lies between two
  // edges.
  cv::Mat one = cv::Mat::zeros(100, 100, CV_8U);
  cv::line(one, {20, 20}, {20, 69}, 255);
  EXPECT_EQ(cv::countNonZero(KeepEnclosed(sil, one, 1, 0)), 50);
  // An edge just outside the run counts within the reach.
  cv::Mat outside = cv::Mat::zeros(100, 100, CV_8U);
  cv::rectangle(outside, cv::Rect(18, 18, 44, 54), 255, 1);
  EXPECT_EQ(cv::countNonZero(KeepEnclosed(sil, outside, 4, 0)), 0);
  EXPECT_EQ(cv::countNonZero(KeepEnclosed(sil, outside, 4, 2)), 40 * 50);
}

// A sharp-edged body with a soft shadow attached at its feet, on a grainy
// stage: the shadow goes, the body stays.
TEST(ShadowRemoverTest, RemovesASoftShadowAndKeepsTheBody) {
  std::mt19937 rng(3);
  std::normal_distribution<float> grain(0, 2.0f);
  auto stage = [&] {
    cv::Mat f(240, 320, CV_32F);
    for (int y = 0; y < 240; ++y)
      for (int x = 0; x < 320; ++x) f.at<float>(y, x) = 70 + 20.0f * y / 240 + grain(rng);
    return f;
  };
  auto to8 = [](const cv::Mat& f) {
    cv::Mat out;
    f.convertTo(out, CV_8U);
    return out;
  };
  std::vector<cv::Mat> background, background_copy;
  for (int i = 0; i < 8; ++i) {
    background.push_back(to8(stage()));
    background_copy.push_back(background.back().clone());
  }
  const auto remover = ShadowRemover::Train(background, {});
  ASSERT_TRUE(remover);
  // Training reads the empty-stage frames and leaves them as they were (its
  // blur once wrote into them).
  for (int i = 0; i < 8; ++i) EXPECT_EQ(cv::norm(background[i], background_copy[i], cv::NORM_INF), 0) << i;

  cv::Mat body = cv::Mat::zeros(240, 320, CV_8U);
  cv::ellipse(body, {160, 110}, {22, 90}, 0, 0, 360, 255, cv::FILLED);
  // The shadow: a region darkening the floor by up to 35%, with a blurry edge
  // (a Gaussian penumbra of sigma 14 px, as light diffused off the screen
  // gives), reaching from the feet to the right.
  cv::Mat shade = cv::Mat::zeros(240, 320, CV_32F);
  cv::ellipse(shade, {220, 200}, {75, 26}, 0, 0, 360, 1.0, cv::FILLED);
  cv::GaussianBlur(shade, shade, cv::Size(), 14);
  cv::Mat frame = stage();
  frame = frame.mul(1.0 - 0.35 * shade);
  frame.setTo(150, body);
  const cv::Mat image = to8(frame);
  // What background subtraction would give: the body and the shadow's core.
  cv::Mat shadow = (shade > 0.3) & ~body;
  cv::Mat silhouette = body | shadow;
  const cv::Mat image_copy = image.clone();
  const cv::Mat out = remover->Remove(image, silhouette);
  EXPECT_EQ(cv::norm(image, image_copy, cv::NORM_INF), 0);  // the frame is read, not written
  const double shadow_left = double(cv::countNonZero(out & shadow)) / cv::countNonZero(shadow);
  const double body_lost = 1.0 - double(cv::countNonZero(out & body)) / cv::countNonZero(body);
  std::printf("shadow pixels left %.1f%%, body pixels lost %.2f%%\n", 100 * shadow_left, 100 * body_lost);
  EXPECT_LT(shadow_left, 0.10);
  EXPECT_LT(body_lost, 0.03);
}

}  // namespace
}  // namespace irbench
