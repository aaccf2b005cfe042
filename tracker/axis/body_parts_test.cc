// Body parts (thesis 3.3) on a drawn stick figure with known parts.

#include "common/error.h"
#include "tracker/axis/body_parts.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

namespace irbench {
namespace {

double DistanceToSegment(const Eigen::Vector2d& p, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  const double s = std::clamp((p - a).dot(b - a) / (b - a).squaredNorm(), 0.0, 1.0);
  return (a + s * (b - a) - p).norm();
}

// A person facing the camera: the image-left arm raised diagonally, the
// image-right arm horizontal, legs apart.
struct StickFigure {
  Eigen::Vector2d head{160, 58};
  Eigen::Vector2d left_shoulder{150, 100}, left_hand{95, 40};
  Eigen::Vector2d right_shoulder{170, 100}, right_hand{255, 100};
  cv::Mat1b image = cv::Mat1b(240, 320, uchar(0));
  StickFigure() {
    cv::ellipse(image, {160, 130}, {22, 45}, 0, 0, 360, 255, cv::FILLED);  // torso, rows 85..175
    cv::circle(image, {160, 58}, 12, 255, cv::FILLED);
    cv::line(image, {160, 68}, {160, 88}, 255, 10);  // neck
    cv::line(image, {150, 100}, {95, 40}, 255, 8);
    cv::line(image, {170, 100}, {255, 100}, 255, 8);
    cv::line(image, {150, 165}, {140, 228}, 255, 14);
    cv::line(image, {170, 165}, {180, 228}, 255, 14);
  }
};

TEST(BodyPartsTest, StickFigurePartsAreLabelledRight) {
  const StickFigure figure;
  const AxisGraph graph = ExtractAxisPoints(figure.image);
  const auto parts = SegmentBodyParts(figure.image, graph);
  ASSERT_TRUE(parts.has_value());
  EXPECT_NEAR(parts->torso_column_px, 160, 2);
  // The ellipse's rounded top (row 85) is thinner than the torso threshold
  // (0.6 x its 44 px width) down to about row 92.
  EXPECT_NEAR(parts->torso_top_row, 90, 3);
  EXPECT_NEAR(parts->head_top_row, 46, 2);
  EXPECT_GT(parts->torso.size(), 40u);
  for (int i : parts->head) {
    EXPECT_NEAR(graph.points[i].px.x(), 160, 1.0);
    EXPECT_LT(graph.points[i].px.y(), 93);
  }
  EXPECT_GT(parts->head.size(), 30u);
  // Each arm: many points, all on its drawn segment, none on the other arm or the legs.
  ASSERT_GT(parts->left_arm.size(), 40u);
  ASSERT_GT(parts->right_arm.size(), 40u);
  // cv::line's round caps (radius 4) add up to 4 px beyond the hand.
  for (int i : parts->left_arm) {
    EXPECT_LT(DistanceToSegment(graph.points[i].px, figure.left_shoulder, figure.left_hand), 4.0)
        << graph.points[i].px.transpose();
  }
  int checked = 0;
  for (int i : parts->right_arm) {
    const Eigen::Vector2d& px = graph.points[i].px;
    EXPECT_LT(DistanceToSegment(px, figure.right_shoulder, figure.right_hand), 4.0) << px.transpose();
    if (px.x() < figure.right_hand.x() - 4) {  // off the cap: on the axis, 8 px thick
      ++checked;
      EXPECT_LT(DistanceToSegment(px, figure.right_shoulder, figure.right_hand), 1.0) << px.transpose();
      EXPECT_NEAR(graph.points[i].diameter_px, 8, 1.5) << px.transpose();
    }
  }
  EXPECT_GT(checked, 40);
  // The arms reach their hands; ordered from the shoulder outwards.
  EXPECT_LT((graph.points[parts->left_arm.back()].px - figure.left_hand).norm(), 8);
  EXPECT_LT((graph.points[parts->right_arm.back()].px - figure.right_hand).norm(), 8);
  for (size_t i = 0; i < graph.points.size(); ++i) {
    EXPECT_EQ(parts->labels[i] == BodyPart::kLeftImageArm,
              std::find(parts->left_arm.begin(), parts->left_arm.end(), int(i)) != parts->left_arm.end());
  }
}

TEST(BodyPartsTest, MirroredFigureSwapsTheImageArms) {
  StickFigure figure;
  cv::Mat1b mirrored;
  cv::flip(figure.image, mirrored, 1);  // u -> 319 - u
  const AxisGraph graph = ExtractAxisPoints(mirrored);
  const auto parts = SegmentBodyParts(mirrored, graph);
  ASSERT_TRUE(parts.has_value());
  ASSERT_GT(parts->left_arm.size(), 40u);
  for (int i : parts->left_arm) {  // the horizontal arm, now on the left
    EXPECT_NEAR(graph.points[i].px.y(), 100, 4.0);
  }
}

TEST(BodyPartsTest, NoBlobGivesNothing) {
  cv::Mat1b empty(240, 320, uchar(0));
  EXPECT_FALSE(SegmentBodyParts(empty, ExtractAxisPoints(empty)).has_value());
  BodyPartOptions options;
  options.arm_max_width_fraction = 0;
  EXPECT_THROW(options.Check(), InputError);
}

}  // namespace
}  // namespace irbench
