// NSS skeletons (thesis 4.4.1) on voxelised stick figures whose bones are
// known: every limb found, labelled, and its curve within 3 cm of the bone;
// Isomap straightens a bent limb (its ends as far apart in the embedding as
// along the body).

#include "tracker/nss/nss_skeleton.h"

#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "common/error.h"
#include "tracker/nss/stick_figure.h"

namespace irbench {
namespace {

using irbench::testing::DistanceToPolyline;
using irbench::testing::MakeStickFigure;
using irbench::testing::StickFigure;

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 1e9 : v[v.size() / 2];
}

// Every limb's curve: labelled, median distance to its true bone under 3 cm,
// its tip near the bone's end.
void ExpectLimbsOnTheBones(const StickFigure& figure, const NssSkeleton& skeleton) {
  for (const auto& [label, bone] : figure.bones) {
    const NssCurve* curve = skeleton.Find(label);
    ASSERT_NE(curve, nullptr) << "no " << label;
    std::vector<double> distances;
    for (const Eigen::Vector3d& p : curve->points_in_world) distances.push_back(DistanceToPolyline(p, bone));
    EXPECT_LT(Median(distances), 0.03) << label;
    const double tip_to_end = (curve->points_in_world.back() - bone.back()).norm();
    EXPECT_LT(tip_to_end, 0.08) << label;
    std::printf("%-10s %2zu nodes, %.2f m, median %.1f cm from the bone, tip %.1f cm from its end\n", label.c_str(),
                curve->points_in_world.size(), curve->length_m, 100 * Median(distances), 100 * tip_to_end);
  }
  const NssCurve* torso = skeleton.Find("torso");
  ASSERT_NE(torso, nullptr);
  // The torso runs from the pelvis up to the shoulders, near the body's axis.
  EXPECT_LT(torso->points_in_world.front().z(), 1.05);
  EXPECT_GT(torso->points_in_world.back().z(), 1.25);
  for (const Eigen::Vector3d& p : torso->points_in_world) EXPECT_LT(p.head<2>().norm(), 0.06);
}

TEST(NssSkeletonTest, ArmRaisedSidewaysAndForearmForward) {
  // Right arm raised out to the side, left forearm bent forward at the elbow.
  const StickFigure figure = MakeStickFigure({0.45, 0, 1.55}, {0.65, 0, 1.75}, {-0.3, 0.1, 1.15}, {-0.26, 0.37, 1.15});
  const NssSkeleton skeleton = ComputeNssSkeleton(figure.hull, {0, 1});
  EXPECT_GT(skeleton.voxels, 3000);
  ExpectLimbsOnTheBones(figure, skeleton);
}

TEST(NssSkeletonTest, BothArmsOverheadTheHeadIsTheShortUpperBranch) {
  const StickFigure figure = MakeStickFigure({0.28, 0.02, 1.68}, {0.3, 0.05, 1.98}, {-0.28, 0.02, 1.68}, {-0.3, 0.05, 1.98});
  ExpectLimbsOnTheBones(figure, ComputeNssSkeleton(figure.hull, {0, 1}));
}

TEST(NssSkeletonTest, FacingDecidesLeftAndRight) {
  // The same figure, said to face -y: its +x arm is now its left.
  const StickFigure figure = MakeStickFigure({0.45, 0, 1.55}, {0.65, 0, 1.75}, {-0.3, 0.1, 1.15}, {-0.26, 0.37, 1.15});
  const NssSkeleton skeleton = ComputeNssSkeleton(figure.hull, {0, -1});
  const NssCurve* left = skeleton.Find("left_arm");
  ASSERT_NE(left, nullptr);
  EXPECT_GT(left->points_in_world.back().x(), 0.5);
  const NssCurve* right_leg = skeleton.Find("right_leg");
  ASSERT_NE(right_leg, nullptr);
  EXPECT_LT(right_leg->points_in_world.back().x(), 0);
}

TEST(NssSkeletonTest, IsomapStraightensABentTube) {
  // A U of 2 cm voxels: two 40 cm legs 20 cm apart joined at the bottom.
  VoxelHull hull;
  hull.voxel_size_m = 0.02;
  hull.nx = 20, hull.ny = 4, hull.nz = 24;
  hull.occupied.assign(size_t(hull.nx) * hull.ny * hull.nz, 0);
  std::vector<Eigen::Vector3i> cells;
  for (int z = 0; z < hull.nz; ++z) {
    for (int y = 0; y < hull.ny; ++y) {
      for (int x = 0; x < hull.nx; ++x) {
        if (z < 4 || x < 4 || x >= 16) {
          hull.occupied[hull.Index(x, y, z)] = 1;
          cells.emplace_back(x, y, z);
        }
      }
    }
  }
  // Geodesics follow the tube: from the top of one leg to the top of the other.
  const auto find = [&](int x, int y, int z) {
    return static_cast<int>(std::find(cells.begin(), cells.end(), Eigen::Vector3i(x, y, z)) - cells.begin());
  };
  const int a = find(1, 1, 23), b = find(18, 1, 23);
  const std::vector<double> d = VoxelGeodesics(cells, 0.02, a);
  const double euclid = 0.02 * 17, along = d[b];
  EXPECT_GT(along, 2.5 * euclid);  // down 44 cm, across 34, up 44: about 1.1 m
  EXPECT_LT(along, 1.3);
  // The embedding puts the two tops about as far apart as along the tube.
  NssOptions options;
  options.landmarks = 24;
  const NssSkeleton skeleton = ComputeNssSkeleton(hull, {0, 1}, options);
  ASSERT_EQ(skeleton.embedded.size(), cells.size());
  const auto embedded_at = [&](const Eigen::Vector3d& centre) {
    for (size_t i = 0; i < skeleton.voxel_centres.size(); ++i) {
      if ((skeleton.voxel_centres[i] - centre).norm() < 1e-9) return skeleton.embedded[i];
    }
    ADD_FAILURE() << "no voxel at " << centre.transpose();
    return Eigen::Vector3d(0, 0, 0);
  };
  const double embedded = (embedded_at(hull.VoxelCenter(1, 1, 23)) - embedded_at(hull.VoxelCenter(18, 1, 23))).norm();
  std::printf("ends: %.2f m apart, %.2f m along the tube, %.2f m in the embedding\n", euclid, along, embedded);
  EXPECT_GT(embedded, 0.85 * along);
}

TEST(NssSkeletonTest, PlyHoldsEveryCurvePointAndTheEdgesBetweenThem) {
  const StickFigure figure = MakeStickFigure({0.45, 0, 1.55}, {0.65, 0, 1.75}, {-0.3, 0.1, 1.15}, {-0.26, 0.37, 1.15});
  const NssSkeleton skeleton = ComputeNssSkeleton(figure.hull, {0, 1});
  const std::filesystem::path path = std::filesystem::temp_directory_path() / ("nss_" + std::to_string(getpid()) + ".ply");
  WriteNssPly(path, skeleton);
  std::ifstream in(path);
  std::string line;
  int vertices = -1, edges = -1;
  while (std::getline(in, line) && line != "end_header") {
    std::sscanf(line.c_str(), "element vertex %d", &vertices);
    std::sscanf(line.c_str(), "element edge %d", &edges);
  }
  size_t points = 0, segments = 0;
  for (const NssCurve& c : skeleton.curves) points += c.points_in_world.size(), segments += c.points_in_world.size() - 1;
  EXPECT_EQ(vertices, static_cast<int>(points));
  EXPECT_EQ(edges, static_cast<int>(segments));
  // The first vertex is the first curve's first point; the edges join its neighbours.
  double x, y, z;
  int r, g, b;
  ASSERT_TRUE(std::getline(in, line));
  ASSERT_EQ(std::sscanf(line.c_str(), "%lf %lf %lf %d %d %d", &x, &y, &z, &r, &g, &b), 6);
  EXPECT_NEAR(x, skeleton.curves[0].points_in_world[0].x(), 1e-4);
  EXPECT_NEAR(z, skeleton.curves[0].points_in_world[0].z(), 1e-4);
  for (int i = 1; i < vertices; ++i) std::getline(in, line);
  int a = -1, c = -1;
  ASSERT_TRUE(std::getline(in, line));
  ASSERT_EQ(std::sscanf(line.c_str(), "%d %d", &a, &c), 2);
  EXPECT_EQ(a, 0);
  EXPECT_EQ(c, 1);
  std::filesystem::remove(path);
}

TEST(NssSkeletonTest, SmallOrEmptyHullsGiveNoSkeletonAndBadOptionsAreRefused) {
  VoxelHull hull;
  hull.voxel_size_m = 0.02;
  hull.nx = hull.ny = hull.nz = 4;
  hull.occupied.assign(64, 0);
  EXPECT_TRUE(ComputeNssSkeleton(hull, {0, 1}).nodes.empty());
  hull.occupied[5] = 1;
  const NssSkeleton one = ComputeNssSkeleton(hull, {0, 1});
  EXPECT_EQ(one.voxels, 1);
  EXPECT_TRUE(one.curves.empty());
  NssOptions bad;
  bad.landmarks = 2;
  EXPECT_THROW(ComputeNssSkeleton(hull, {0, 1}, bad), InputError);
  bad = {};
  bad.shell_width_m = 0;
  EXPECT_THROW(ComputeNssSkeleton(hull, {0, 1}, bad), InputError);
}

}  // namespace
}  // namespace irbench
