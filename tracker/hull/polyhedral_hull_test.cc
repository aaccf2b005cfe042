#include "tracker/hull/polyhedral_hull.h"

#include <gtest/gtest.h>

#include "common/error.h"
#include "tracker/hull/hull_test_util.h"
#include "tracker/hull/voxel_hull.h"

namespace irbench {
namespace {
using irbench::testing::BoxSilhouette;
using irbench::testing::HullRig;
using irbench::testing::SphereSilhouette;

using irbench::testing::kSphereCentre;
using irbench::testing::kSphereRadius;

// Distance from a pixel to the nearest polygon edge.
double DistanceToBoundary(const SilhouettePolygons& poly, const Eigen::Vector2d& px) {
  double best = 1e9;
  for (const auto& loop : poly.loops) {
    for (size_t i = 0; i < loop.vertices.size(); ++i) {
      const Eigen::Vector2d a = loop.vertices[i], b = loop.vertices[(i + 1) % loop.vertices.size()];
      const double t = std::clamp((px - a).dot(b - a) / (b - a).squaredNorm(), 0.0, 1.0);
      best = std::min(best, (a + t * (b - a) - px).norm());
    }
  }
  return best;
}

struct Scene {
  std::vector<Camera> cams;
  std::vector<cv::Mat> masks;
  std::vector<SilhouettePolygons> polys;
};

Scene SphereScene(int ring, int high) {
  Scene s;
  s.cams = HullRig(ring, high);
  for (const Camera& cam : s.cams) {
    s.masks.push_back(SphereSilhouette(cam, kSphereCentre, kSphereRadius));
    s.polys.push_back(ApproximateSilhouette(s.masks.back()));
  }
  return s;
}

TEST(PolyhedralHullTest, SphereHullLiesOnOrOutsideTheSphereAndInsideTheVoxelHull) {
  const Scene s = SphereScene(6, 2);
  const auto mesh = PolyhedralVisualHull(s.cams, s.polys);
  ASSERT_TRUE(mesh.has_value());
  // The polygons lie half a pixel outside the mask's pixel centres: compare
  // with a voxel hull whose margin covers that (and the pixel-centre
  // rasterisation).
  VoxelGridOptions strict;
  strict.margin_px = 0.75;
  const VoxelHull voxels = VoxelCarver(s.cams, strict).Carve(s.masks);
  // Polygon vertices are contour pixel centres (up to half a pixel inside the
  // true outline) and edges are chords (a sagitta of under a pixel at ~25
  // edges): allow 1.5 px at the sphere's distance, 3.5 m / 260 px.
  const double tolerance_m = 1.5 * 3.6 / 260;
  double nearest = 1e9;
  int outside_voxels = 0;
  std::vector<size_t> used;
  for (const auto& t : mesh->triangles) used.insert(used.end(), t.begin(), t.end());
  for (size_t i : used) {
    const Eigen::Vector3d& p = mesh->vertices[i];
    nearest = std::min(nearest, (p - kSphereCentre).norm());
    outside_voxels += !voxels.ContainsPoint(p);
  }
  EXPECT_GE(nearest, kSphereRadius - tolerance_m);
  EXPECT_EQ(outside_voxels, 0) << "of " << used.size();
  // Every vertex projects into every view's polygon (or onto its edge): it
  // lies on the cones' intersection.
  int off_polygon = 0;
  for (size_t i : used) {
    for (size_t c = 0; c < s.cams.size(); ++c) {
      const Eigen::Vector2d px = s.cams[c].Project(mesh->vertices[i]);
      if (!s.polys[c].Contains(px) && DistanceToBoundary(s.polys[c], px) > 0.05) ++off_polygon;
    }
  }
  EXPECT_EQ(off_polygon, 0);
  const double sphere = 4.0 / 3.0 * M_PI * std::pow(kSphereRadius, 3);
  const double volume = MeshVolume(*mesh);
  std::printf("polyhedral sphere hull, 8 cameras: %zu triangles, volume ratio %.3f (voxel %.3f)\n",
              mesh->triangles.size(), volume / sphere, voxels.VolumeM3() / sphere);
  EXPECT_GT(volume, 0.95 * sphere);
  EXPECT_LT(volume, 1.3 * sphere);
  EXPECT_LT(volume, voxels.VolumeM3());
}

TEST(PolyhedralHullTest, BoxHullContainsTheBox) {
  const Eigen::Vector3d lo(-0.35, -0.2, 0.4), hi(0.25, 0.3, 1.6);
  const std::vector<Camera> cams = HullRig(4, 1);
  std::vector<SilhouettePolygons> polys;
  for (const Camera& cam : cams) polys.push_back(ApproximateSilhouette(BoxSilhouette(cam, lo, hi)));
  const auto mesh = PolyhedralVisualHull(cams, polys);
  ASSERT_TRUE(mesh.has_value());
  const double tolerance_m = 1.0 * 3.6 / 260;
  int inside = 0;
  for (const auto& t : mesh->triangles) {
    for (uint32_t i : t) {
      const Eigen::Vector3d p = mesh->vertices[i];
      // Depth inside the box (negative outside).
      const double depth = std::min((p - lo).minCoeff(), (hi - p).minCoeff());
      inside += depth > tolerance_m;
    }
  }
  EXPECT_EQ(inside, 0);
  const double ratio = MeshVolume(*mesh) / (hi - lo).prod();
  std::printf("polyhedral box hull, 5 cameras: volume ratio %.3f\n", ratio);
  EXPECT_GT(ratio, 0.97);
  EXPECT_LT(ratio, 1.8);
}

TEST(PolyhedralHullTest, EmptyAndBadInput) {
  const Scene s = SphereScene(4, 0);
  std::vector<SilhouettePolygons> polys = s.polys;
  polys[2].loops.clear();  // a camera that sees the sphere reports nothing
  EXPECT_FALSE(PolyhedralVisualHull(s.cams, polys).has_value());
  polys.pop_back();
  EXPECT_THROW(PolyhedralVisualHull(s.cams, polys), InputError);
  PolyhedralHullOptions bad;
  bad.ray_step_px = 0;
  EXPECT_THROW(bad.Check(), InputError);
}

TEST(PolyhedralHullTest, MeshVolumeOfAUnitCube) {
  HullMesh cube;
  for (int i = 0; i < 8; ++i) cube.vertices.emplace_back(i & 1, (i >> 1) & 1, (i >> 2) & 1);
  cube.triangles = {{0, 2, 3}, {0, 3, 1}, {4, 5, 7}, {4, 7, 6}, {0, 1, 5}, {0, 5, 4},
                    {2, 6, 7}, {2, 7, 3}, {0, 4, 6}, {0, 6, 2}, {1, 3, 7}, {1, 7, 5}};
  EXPECT_NEAR(MeshVolume(cube), 1.0, 1e-12);
  for (auto& v : cube.vertices) v += Eigen::Vector3d(3, -2, 1);
  EXPECT_NEAR(MeshVolume(cube), 1.0, 1e-12);
}

}  // namespace
}  // namespace irbench
