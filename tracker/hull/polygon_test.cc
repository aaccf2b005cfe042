#include "tracker/hull/polygon.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "common/error.h"

namespace irbench {
namespace {

// A person about 120 px tall, as a 320 x 240 camera 4 m away sees one: head,
// torso, one arm down and one raised sideways, legs apart.
cv::Mat BodyMask() {
  cv::Mat m = cv::Mat::zeros(240, 320, CV_8UC1);
  cv::circle(m, {160, 52}, 10, 255, cv::FILLED);
  cv::line(m, {160, 60}, {160, 68}, 255, 8);
  cv::ellipse(m, {160, 92}, {19, 29}, 0, 0, 360, 255, cv::FILLED);
  cv::line(m, {145, 72}, {128, 100}, 255, 8);
  cv::line(m, {128, 100}, {122, 128}, 255, 7);
  cv::line(m, {175, 72}, {200, 62}, 255, 8);
  cv::line(m, {200, 62}, {226, 50}, 255, 7);
  cv::line(m, {152, 115}, {146, 145}, 255, 12);
  cv::line(m, {146, 145}, {143, 176}, 255, 10);
  cv::line(m, {168, 115}, {176, 145}, 255, 12);
  cv::line(m, {176, 145}, {181, 176}, 255, 10);
  return m;
}

double Iou(const cv::Mat& a, const cv::Mat& b) {
  cv::Mat i, u;
  cv::bitwise_and(a, b, i);
  cv::bitwise_or(a, b, u);
  return double(cv::countNonZero(i)) / cv::countNonZero(u);
}

// Distance from `p` to the nearest pixel centre where `mask` is set.
double DistanceToMask(const cv::Mat& mask, const Eigen::Vector2d& p) {
  double best = 1e9;
  for (int v = 0; v < mask.rows; ++v) {
    for (int u = 0; u < mask.cols; ++u) {
      if (mask.at<uint8_t>(v, u)) best = std::min(best, (Eigen::Vector2d(u, v) - p).norm());
    }
  }
  return best;
}

TEST(PolygonTest, BodySilhouetteHas20To30Edges) {
  const cv::Mat mask = BodyMask();
  const SilhouettePolygons poly = ApproximateSilhouette(mask);
  ASSERT_EQ(poly.loops.size(), 1u);
  EXPECT_GE(poly.EdgeCount(), 20);
  EXPECT_LE(poly.EdgeCount(), 30);
  // Thesis 6.2.1: "approximated by 20-30 polygon edges with reasonable accuracy".
  EXPECT_GT(Iou(RasterizePolygons(poly), mask), 0.85);
  // Vertices are contour pixels moved half a pixel outwards (a mitred corner
  // moves at most 2 x 0.5 px).
  for (const auto& v : poly.loops[0].vertices) EXPECT_LE(DistanceToMask(mask, v), 1.0 + 1e-9);
  std::printf("body silhouette: %d edges at epsilon %.2f px, IoU %.3f\n", poly.EdgeCount(),
              poly.epsilon_px, Iou(RasterizePolygons(poly), mask));
}

TEST(PolygonTest, DiskVerticesLieOnTheCircle) {
  cv::Mat mask = cv::Mat::zeros(240, 320, CV_8UC1);
  cv::circle(mask, {150, 110}, 60, 255, cv::FILLED);
  const SilhouettePolygons poly = ApproximateSilhouette(mask);
  ASSERT_EQ(poly.loops.size(), 1u);
  EXPECT_LE(poly.EdgeCount(), 30);
  EXPECT_GE(poly.EdgeCount(), 12);
  // cv::circle fills pixel centres within 60 px; the outline is half a pixel
  // further out, where the offset vertices lie.
  for (const auto& v : poly.loops[0].vertices)
    EXPECT_NEAR((v - Eigen::Vector2d(150, 110)).norm(), 60.5, 0.75);
  PolygonOptions centres;
  centres.outward_offset_px = 0;
  const SilhouettePolygons on_centres = ApproximateSilhouette(mask, centres);
  for (const auto& v : on_centres.loops[0].vertices) {
    EXPECT_EQ(mask.at<uint8_t>(int(v.y()), int(v.x())), 255);
    EXPECT_NEAR((v - Eigen::Vector2d(150, 110)).norm(), 60, 0.75);
  }
  EXPECT_GT(Iou(RasterizePolygons(poly), mask), 0.97);
}

TEST(PolygonTest, FixedToleranceBoundsTheDeviation) {
  const cv::Mat mask = BodyMask();
  PolygonOptions options;
  int last = 1 << 30;
  for (double eps : {1.0, 2.0, 4.0, 8.0}) {
    options.epsilon_px = eps;
    const SilhouettePolygons poly = ApproximateSilhouette(mask, options);
    EXPECT_EQ(poly.epsilon_px, eps);
    EXPECT_LE(poly.EdgeCount(), last);
    last = poly.EdgeCount();
    // Douglas-Peucker: every point of the polygon is within eps of the contour,
    // so within eps (+ half a pixel of rasterisation) of a silhouette pixel.
    for (const auto& loop : poly.loops) {
      for (size_t i = 0; i < loop.vertices.size(); ++i) {
        const Eigen::Vector2d mid =
            0.5 * (loop.vertices[i] + loop.vertices[(i + 1) % loop.vertices.size()]);
        EXPECT_LE(DistanceToMask(mask, mid), eps + 0.5 + 0.75) << eps;
      }
    }
  }
}

TEST(PolygonTest, HolesAndTinyBlobs) {
  cv::Mat mask = cv::Mat::zeros(240, 320, CV_8UC1);
  cv::circle(mask, {100, 120}, 50, 255, cv::FILLED);
  cv::circle(mask, {100, 120}, 20, 0, cv::FILLED);                   // a hole (arms akimbo)
  cv::rectangle(mask, cv::Rect(250, 30, 3, 3), 255, cv::FILLED);     // a speck
  cv::rectangle(mask, cv::Rect(230, 150, 30, 40), 255, cv::FILLED);  // a second blob
  const SilhouettePolygons poly = ApproximateSilhouette(mask);
  ASSERT_EQ(poly.loops.size(), 3u);
  int holes = 0;
  for (const auto& loop : poly.loops) {
    if (!loop.hole) continue;
    ++holes;
    ASSERT_GE(loop.parent, 0);
    EXPECT_FALSE(poly.loops[loop.parent].hole);
  }
  EXPECT_EQ(holes, 1);
  EXPECT_FALSE(poly.Contains({100, 120}));  // in the hole
  EXPECT_TRUE(poly.Contains({100, 85}));    // in the ring
  EXPECT_TRUE(poly.Contains({245, 170}));   // in the second blob
  EXPECT_FALSE(poly.Contains({251, 31}));   // the dropped speck
  EXPECT_GT(Iou(RasterizePolygons(poly), mask), 0.95);
  // Offsets grow the silhouette: the outer loop outwards, the hole inwards.
  for (const auto& loop : poly.loops) {
    const bool ring = (loop.vertices[0] - Eigen::Vector2d(100, 120)).norm() < 80;
    if (!loop.hole && ring) {
      for (const auto& v : loop.vertices)
        EXPECT_NEAR((v - Eigen::Vector2d(100, 120)).norm(), 50.5, 0.75);
    }
    if (loop.hole) {
      for (const auto& v : loop.vertices)
        EXPECT_NEAR((v - Eigen::Vector2d(100, 120)).norm(), 20.5, 0.75);
    }
  }

  PolygonOptions no_holes;
  no_holes.keep_holes = false;
  EXPECT_EQ(ApproximateSilhouette(mask, no_holes).loops.size(), 2u);
}

TEST(PolygonTest, EmptyMaskAndBadOptions) {
  EXPECT_TRUE(ApproximateSilhouette(cv::Mat::zeros(240, 320, CV_8UC1)).loops.empty());
  PolygonOptions bad;
  bad.epsilon_px = -1;
  EXPECT_THROW(bad.Check(), InputError);
  bad = {};
  bad.max_edges = 10;
  EXPECT_THROW(bad.Check(), InputError);
  bad = {};
  bad.outward_offset_px = -0.5;
  EXPECT_THROW(bad.Check(), InputError);
  EXPECT_NO_THROW(PolygonOptions{}.Check());
}

}  // namespace
}  // namespace irbench
