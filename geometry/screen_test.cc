#include "geometry/screen.h"

#include <gtest/gtest.h>

#include <cmath>

namespace irbench {
namespace {

TEST(ScreenTest, CylinderScreenCoordinatesAreArcLengthFromTheLeftEdge) {
  ScreenSurface screen;
  screen.kind = ScreenSurface::Kind::kCylinder;
  screen.radius = 4.0;
  screen.angle_left_deg = 150;
  screen.angle_right_deg = 30;
  screen.z0 = 1.0;
  screen.z1 = 3.0;
  EXPECT_NEAR(screen.Size().x(), 4.0 * 120 * M_PI / 180, 1e-12);
  // The middle of the arc is straight ahead (+y) of the centre.
  const Eigen::Vector3d mid = screen.PointAt({screen.Size().x() / 2, 0.5});
  EXPECT_NEAR(mid.x(), 0, 1e-12);
  EXPECT_NEAR(mid.y(), 4.0, 1e-12);
  EXPECT_NEAR(mid.z(), 1.5, 1e-12);
  // s grows towards the viewer's right (+x when facing +y).
  EXPECT_LT(screen.PointAt({1.0, 0}).x(), screen.PointAt({2.0, 0}).x());
  // Looking backwards misses.
  EXPECT_FALSE(screen.Intersect({0, 0, 1.5}, {0, -1, 0}).has_value());
}

TEST(ScreenTest, PlaneScreenIsHitOnlyFromTheFront) {
  ScreenSurface screen;
  screen.origin = {-1, 3, 0.5};
  screen.right = {1, 0, 0};
  screen.up = {0, 0, 1};
  screen.width = 2;
  screen.height = 1.5;
  const auto hit = screen.Intersect({0, 0, 1}, {0, 1, 0});
  ASSERT_TRUE(hit.has_value());
  EXPECT_NEAR(hit->x(), 1.0, 1e-12);
  EXPECT_NEAR(hit->y(), 0.5, 1e-12);
  EXPECT_FALSE(screen.Intersect({0, 5, 1}, {0, -1, 0}).has_value());
}

// A ray from the screen's own point back out along the normal hits that point,
// for both kinds, and NearestTarget picks the closest named target.
TEST(ScreenTest, IntersectInvertsPointAtAndNearestTargetIsTheClosest) {
  ScreenSurface plane;
  plane.origin = {-1.5, 3.48, 0.6};
  plane.right = {1, 0, 0};
  plane.up = {0, 0, 1};
  plane.width = 3.0;
  plane.height = 1.9;
  plane.targets = {{"left", {0.5, 1.0}}, {"right", {2.5, 1.0}}};
  ScreenSurface cylinder;
  cylinder.kind = ScreenSurface::Kind::kCylinder;
  cylinder.radius = 3.0;
  cylinder.z0 = 0.2;
  cylinder.z1 = 2.4;
  for (const ScreenSurface* screen : {&plane, &cylinder}) {
    for (double s = 0.1; s < screen->Size().x(); s += 0.37) {
      for (double t = 0.1; t < screen->Size().y(); t += 0.41) {
        const Eigen::Vector3d p = screen->PointAt({s, t});
        const Eigen::Vector3d eye(0.1, 0.2, 1.5);
        const auto hit = screen->Intersect(eye, (p - eye).normalized());
        ASSERT_TRUE(hit.has_value()) << s << " " << t;
        EXPECT_NEAR(hit->x(), s, 1e-9);
        EXPECT_NEAR(hit->y(), t, 1e-9);
      }
    }
  }
  EXPECT_EQ(plane.NearestTarget({0.9, 0.2}), "left");
  EXPECT_EQ(plane.NearestTarget({1.6, 1.7}), "right");
  EXPECT_EQ(cylinder.NearestTarget({0.5, 0.5}), "");
}

}  // namespace
}  // namespace irbench
