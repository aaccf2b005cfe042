// 2D axis points (thesis 3.2) on silhouettes whose axis and width are known
// analytically.

#include "common/error.h"
#include "tracker/axis/axis_points.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

namespace irbench {
namespace {

constexpr int kShift = 8;  // fixed-point bits for sub-pixel polygon corners

// A filled rectangle (a thick line without caps) centred at `center`, its long
// axis at `angle_deg` from +u, pixels.
cv::Mat1b ThickSegment(const Eigen::Vector2d& center, double angle_deg, double half_length, double width) {
  cv::Mat1b image(240, 320, uchar(0));
  const Eigen::Vector2d along(std::cos(angle_deg * M_PI / 180), std::sin(angle_deg * M_PI / 180));
  const Eigen::Vector2d across(-along.y(), along.x());
  std::vector<cv::Point> corners;
  for (const auto& [s, n] : {std::pair{1, 1}, {1, -1}, {-1, -1}, {-1, 1}}) {
    const Eigen::Vector2d p = center + s * half_length * along + n * 0.5 * width * across;
    corners.emplace_back(int(std::lround(p.x() * (1 << kShift))), int(std::lround(p.y() * (1 << kShift))));
  }
  cv::fillPoly(image, std::vector<std::vector<cv::Point>>{corners}, 255, cv::LINE_8, kShift);
  return image;
}

class ThickSegmentTest : public ::testing::TestWithParam<double> {};

TEST_P(ThickSegmentTest, KeptPointsLieOnTheAxisWithTheWidthAsDiameter) {
  const double angle_deg = GetParam();
  const Eigen::Vector2d center(160.3, 119.6);
  const double half_length = 80, width = 12;
  const AxisGraph graph = ExtractAxisPoints(ThickSegment(center, angle_deg, half_length, width));
  const Eigen::Vector2d along(std::cos(angle_deg * M_PI / 180), std::sin(angle_deg * M_PI / 180));
  int checked = 0;
  double worst_offset = 0, worst_diameter = 0;
  std::vector<double> diameter_errors;
  for (const AxisPoint2d& p : graph.points) {
    if (!p.kept) continue;
    const Eigen::Vector2d x = p.px - center;
    const double s = x.dot(along);
    // Away from the ends, where the runs cut the caps.
    if (std::abs(s) > half_length - width) continue;
    ++checked;
    worst_offset = std::max(worst_offset, std::abs(x.x() * along.y() - x.y() * along.x()));
    worst_diameter = std::max(worst_diameter, std::abs(p.diameter_px - width));
    diameter_errors.push_back(std::abs(p.diameter_px - width));
    // Kept directions are within 22.5 deg of perpendicular, plus what keep_slack
    // lets through where two directions cut nearly alike.
    EXPECT_LT(std::abs(ScanStep(p.direction).dot(along)), std::sin(31 * M_PI / 180)) << angle_deg;
  }
  EXPECT_GT(checked, 100) << angle_deg;  // about one per scan line along the segment
  EXPECT_LE(worst_offset, 1.0) << angle_deg;
  EXPECT_LE(worst_diameter, 2.75) << angle_deg;
  std::nth_element(diameter_errors.begin(), diameter_errors.begin() + diameter_errors.size() / 2,
                   diameter_errors.end());
  // fillPoly includes both edges (a 12 px band rasterises to 12-13 pixels) and
  // the local axis direction from +-3 neighbours is a few degrees off.
  EXPECT_LE(diameter_errors[diameter_errors.size() / 2], 1.6) << angle_deg;
}

INSTANTIATE_TEST_SUITE_P(Angles, ThickSegmentTest, ::testing::Values(0.0, 10.0, 22.0, 30.0, 45.0, 60.0, 80.0,
                                                                     90.0, 115.0, 135.0, 160.0));

TEST(AxisPointsTest, RunLengthsAndMidpointsOfASquare) {
  cv::Mat1b image(100, 120, uchar(0));
  image(cv::Rect(30, 20, 40, 40)) = 255;  // u 30..69, v 20..59
  const AxisGraph graph = ExtractAxisPoints(image);
  int horizontal = 0, main_diagonal = 0;
  for (const AxisPoint2d& p : graph.points) {
    if (p.direction == ScanDirection::kHorizontal) {
      ++horizontal;
      EXPECT_DOUBLE_EQ(p.run_px, 40);
      EXPECT_DOUBLE_EQ(p.px.x(), 49.5);
      EXPECT_DOUBLE_EQ(p.px.y(), p.line);
    }
    // The diagonal through the corners (30, 20) and (69, 59): 40 pixels, sqrt 2 apart.
    if (p.direction == ScanDirection::kDiagonalDown && std::abs(p.px.x() - p.px.y() - 10) < 1e-9) {
      ++main_diagonal;
      EXPECT_NEAR(p.run_px, 40 * std::sqrt(2.0), 1e-9);
      EXPECT_NEAR(p.px.x(), 49.5, 1e-9);
      EXPECT_NEAR(p.px.y(), 39.5, 1e-9);
    }
  }
  EXPECT_EQ(horizontal, 40);
  EXPECT_EQ(main_diagonal, 1);
}

TEST(AxisPointsTest, NeighboursAreAdjacentLinesWithOverlappingRuns) {
  cv::Mat1b image(120, 160, uchar(0));
  cv::ellipse(image, {60, 60}, {40, 25}, 30, 0, 360, 255, cv::FILLED);
  cv::circle(image, {130, 30}, 12, 255, cv::FILLED);  // a separate blob
  const AxisGraph graph = ExtractAxisPoints(image);
  int links = 0;
  for (size_t i = 0; i < graph.points.size(); ++i) {
    const AxisPoint2d& p = graph.points[i];
    for (int n : p.neighbors) {
      const AxisPoint2d& q = graph.points[n];
      ++links;
      EXPECT_EQ(q.direction, p.direction);
      EXPECT_EQ(std::abs(q.line - p.line), 1);
      EXPECT_TRUE(p.t0 <= q.t1 && q.t0 <= p.t1);
      // Symmetric, and never across the two blobs.
      EXPECT_NE(std::find(q.neighbors.begin(), q.neighbors.end(), int(i)), q.neighbors.end());
      EXPECT_EQ(p.px.x() > 105, q.px.x() > 105);
    }
  }
  EXPECT_GT(links, 300);
}

TEST(AxisPointsTest, OptionsRejectBadValues) {
  AxisPointOptions options;
  EXPECT_NO_THROW(options.Check());
  options.min_run_px = 0;
  EXPECT_THROW(options.Check(), InputError);
  options = {};
  options.keep_slack = -0.1;
  EXPECT_THROW(options.Check(), InputError);
  EXPECT_THROW(ExtractAxisPoints(cv::Mat()), std::invalid_argument);
  EXPECT_THROW(ExtractAxisPoints(cv::Mat(10, 10, CV_32F)), std::invalid_argument);
}

}  // namespace
}  // namespace irbench
