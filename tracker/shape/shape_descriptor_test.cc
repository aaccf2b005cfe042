#include "tracker/shape/shape_descriptor.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>
#include <random>

#include "common/error.h"

namespace irbench {
namespace {

int BinIndex(const ShapeDescriptorOptions& o, int k, int l, int p) { return (k * o.theta_bins + l) * o.phi_bins + p; }

// A solid vertical cylinder of voxels: radius 5 voxels, 20 voxels high.
VoxelHull VoxelCylinder() {
  VoxelHull hull;
  hull.origin_m = Eigen::Vector3d(-0.2, -0.2, 0.0);
  hull.voxel_size_m = 0.02;
  hull.nx = hull.ny = 20;
  hull.nz = 30;
  hull.occupied.assign(size_t(hull.nx) * hull.ny * hull.nz, 0);
  for (int z = 0; z < 20; ++z) {
    for (int y = 0; y < hull.ny; ++y) {
      for (int x = 0; x < hull.nx; ++x) {
        const double dx = x - 9.5, dy = y - 9.5;
        if (dx * dx + dy * dy <= 25) {
          hull.occupied[hull.Index(x, y, z)] = 1;
          ++hull.occupied_count;
        }
      }
    }
  }
  return hull;
}

TEST(ShapeDescriptor, SurfaceVoxelsOfACylinder) {
  const VoxelHull hull = VoxelCylinder();
  // Brute force: a voxel is on the surface when a face neighbour is empty
  // or outside the grid.
  int per_layer = 0, rim = 0;
  for (int y = 0; y < hull.ny; ++y) {
    for (int x = 0; x < hull.nx; ++x) {
      if (!hull.Occupied(x, y, 0)) continue;
      ++per_layer;
      bool inner = true;
      for (auto [ex, ey] : {std::pair{1, 0}, {-1, 0}, {0, 1}, {0, -1}}) inner = inner && hull.Occupied(x + ex, y + ey, 0);
      if (!inner) ++rim;
    }
  }
  // The bottom and top layers whole, the 18 between only their rims.
  const std::vector<Eigen::Vector3d> surface = HullSurfacePoints(hull);
  EXPECT_EQ(surface.size(), size_t(2 * per_layer + 18 * rim));
  for (const auto& p : surface) {
    const double r = std::hypot(p.x(), p.y());
    EXPECT_TRUE(p.z() < 0.02 || p.z() > 0.37 || r > 0.07) << p.transpose();
  }
}

// One point on the axis: every reference point of a ring sees it in the
// same place of its own frame, straight inward (phi = pi), so each ring fills
// one bin 16 times. Hand-computed for h = 1.8 m (R = 0.9, largest chord
// sqrt(1.8^2 + 1.8^2) = 2.5456 m), the point at z = 0.75 m, the rings at
// 0.3, 0.9 and 1.5 m:
//   ring 0: d = (-0.9, 0, 0.45): |d| = 1.0062, r = 0.3953 -> bin 9;
//           theta = acos(0.4472) = 63.43 deg -> bin 8
//   ring 1: d = (-0.9, 0, -0.15): |d| = 0.9124, r = 0.3584 -> bin 8;
//           theta = 99.46 deg -> bin 13
//   ring 2: d = (-0.9, 0, -0.75): |d| = 1.1715, r = 0.4602 -> bin 11;
//           theta = 129.81 deg -> bin 17
// phi = +-180 deg -> bin 12 (bins centred on multiples of 15 deg).
TEST(ShapeDescriptor, OnePointOnTheAxisMatchesHandComputedBins) {
  ShapeDescriptorOptions o;
  o.smoothing_bins = 0;
  const ShapeDescriptor d = ComputeShapeDescriptor({Eigen::Vector3d(0.3, -0.2, 0.75)}, 1.8, o);
  ASSERT_EQ(d.bins.size(), size_t(24 * 24 * 24));
  EXPECT_EQ(d.point_count, 1);
  EXPECT_EQ(d.NonEmptyBins(), 3);
  EXPECT_EQ(d.bins[BinIndex(o, 9, 8, 12)], 1.0f);
  EXPECT_EQ(d.bins[BinIndex(o, 8, 13, 12)], 1.0f);
  EXPECT_EQ(d.bins[BinIndex(o, 11, 17, 12)], 1.0f);
  EXPECT_NEAR(d.axis_xy.x(), 0.3, 1e-6);
}

// Smoothed, each peak spreads as the product of one Gaussian per axis: a
// neighbour one bin away along one axis holds exp(-1/2) of the peak, two
// axes away exp(-1); phi's neighbours on both sides alike.
TEST(ShapeDescriptor, SmoothingIsAGaussianPerAxis) {
  ShapeDescriptorOptions o;
  o.smoothing_bins = 1.0;
  const ShapeDescriptor d = ComputeShapeDescriptor({Eigen::Vector3d(0.3, -0.2, 0.75)}, 1.8, o);
  const float peak = d.bins[BinIndex(o, 9, 8, 12)];
  EXPECT_FLOAT_EQ(peak, 1.0f);
  EXPECT_NEAR(d.bins[BinIndex(o, 10, 8, 12)], std::exp(-0.5), 1e-5);
  EXPECT_NEAR(d.bins[BinIndex(o, 9, 7, 12)], std::exp(-0.5), 1e-5);
  EXPECT_NEAR(d.bins[BinIndex(o, 9, 8, 11)], std::exp(-0.5), 1e-5);
  EXPECT_NEAR(d.bins[BinIndex(o, 9, 8, 13)], std::exp(-0.5), 1e-5);
  EXPECT_NEAR(d.bins[BinIndex(o, 10, 9, 12)], std::exp(-1.0), 1e-5);
  EXPECT_NEAR(d.bins[BinIndex(o, 9, 8, 15)], std::exp(-4.5), 1e-5);
  EXPECT_EQ(d.bins[BinIndex(o, 9, 8, 16)], 0.0f);  // beyond the kernel's 3 bins
  // A peak at phi bin 12 reaches bins 9..15 only.
  EXPECT_EQ(d.bins[BinIndex(o, 9, 8, 0)], 0.0f);
}

// Off the axis the histogram is the sum over the reference points; two
// points on opposite sides give the same counts as one point does, twice:
// each counts 48 times, the largest bin is normalised to 1.
TEST(ShapeDescriptor, BinsSumToTheReferencePointsTimesThePoints) {
  ShapeDescriptorOptions o;
  o.smoothing_bins = 0;
  o.r_bins = o.theta_bins = o.phi_bins = 8;
  const std::vector<Eigen::Vector3d> points = {{0.2, 0, 1.0}, {-0.2, 0, 1.0}, {0, 0.1, 0.4}};
  const ShapeDescriptor d = ComputeShapeDescriptor(points, 1.7, o);
  double sum = 0, largest = 0;
  for (float b : d.bins) sum += b, largest = std::max<double>(largest, b);
  EXPECT_EQ(largest, 1.0);
  // The largest bin's count: sum / (48 * 3) of the normalised sum gives 1 / count.
  const double count = 48.0 * 3 / sum;
  EXPECT_NEAR(count, std::round(count), 1e-4);
}

// Invariances the thesis claims (4.3): translation, scale (with the user's
// height) and turns about the vertical axis by a multiple of 360/16 degrees.
TEST(ShapeDescriptor, InvariantToTranslationScaleAndTurns) {
  std::mt19937_64 rng(4);
  std::uniform_real_distribution<double> u(-0.3, 0.3), z(0.05, 1.7);
  std::vector<Eigen::Vector3d> body;
  for (int i = 0; i < 600; ++i) body.emplace_back(u(rng), 0.5 * u(rng), z(rng));
  for (int i = 0; i < 100; ++i) body.emplace_back(0.3 + 0.6 * (u(rng) + 0.3), 0.05 * u(rng), 1.4 + 0.1 * u(rng));
  const ShapeDescriptor base = ComputeShapeDescriptor(body, 1.75);

  std::vector<Eigen::Vector3d> moved, scaled, turned, half_turned;
  const Eigen::Matrix3d turn = Eigen::AngleAxisd(3 * 2 * std::numbers::pi / 16, Eigen::Vector3d::UnitZ()).matrix();
  const Eigen::Matrix3d half = Eigen::AngleAxisd(std::numbers::pi / 16, Eigen::Vector3d::UnitZ()).matrix();
  for (const auto& p : body) {
    moved.push_back(p + Eigen::Vector3d(0.7, -0.4, 0));
    scaled.push_back(1.25 * p);
    turned.push_back(turn * p);
    half_turned.push_back(half * p);
  }
  auto max_diff = [&](const ShapeDescriptor& d) {
    float m = 0;
    for (size_t i = 0; i < d.bins.size(); ++i) m = std::max(m, std::abs(d.bins[i] - base.bins[i]));
    return m;
  };
  EXPECT_LT(max_diff(ComputeShapeDescriptor(moved, 1.75)), 1e-6);
  EXPECT_LT(max_diff(ComputeShapeDescriptor(scaled, 1.25 * 1.75)), 0.05);
  EXPECT_LT(max_diff(ComputeShapeDescriptor(turned, 1.75)), 0.05);
  // Between the reference azimuths the descriptor changes, but not much:
  // the histograms' overlap stays high.
  const ShapeDescriptor h = ComputeShapeDescriptor(half_turned, 1.75);
  double dot = 0, n1 = 0, n2 = 0;
  for (size_t i = 0; i < h.bins.size(); ++i) dot += h.bins[i] * base.bins[i], n1 += h.bins[i] * h.bins[i], n2 += base.bins[i] * base.bins[i];
  EXPECT_GT(dot / std::sqrt(n1 * n2), 0.8);
  // A raised arm changes it.
  std::vector<Eigen::Vector3d> arm_down(body.begin(), body.begin() + 600);
  const ShapeDescriptor without = ComputeShapeDescriptor(arm_down, 1.75);
  EXPECT_GT(max_diff(without), 0.1);
}

TEST(ShapeDescriptor, BadOptionsAndHeights) {
  ShapeDescriptorOptions o;
  o.theta_bins = 0;
  EXPECT_THROW(o.Check(), InputError);
  EXPECT_THROW(ComputeShapeDescriptor({Eigen::Vector3d::Zero()}, 0.0), std::invalid_argument);
  const ShapeDescriptor empty = ComputeShapeDescriptor(std::vector<Eigen::Vector3d>{}, 1.7);
  EXPECT_EQ(empty.NonEmptyBins(), 0);
  EXPECT_EQ(empty.point_count, 0);
}

}  // namespace
}  // namespace irbench
