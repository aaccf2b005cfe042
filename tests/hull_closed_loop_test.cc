// Closed loop with the simulator: render a clean sequence, carve the truth
// masks (the test may read truth; the library never does) with the rig's
// calibration as the tracker reads it, and check the hulls against the posed
// avatar mesh. Issue bars: the voxel hull contains at least 98% of points
// sampled inside the true body, and its volume is at most 2x the body's with
// 4 cameras.

#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <opencv2/imgcodecs.hpp>
#include <random>

#include "sim/body/avatar.h"
#include "sim/sequence/render_job.h"
#include "tracker/hull/ply.h"
#include "tracker/hull/polygon.h"
#include "tracker/hull/polyhedral_hull.h"
#include "tracker/hull/voxel_hull.h"
#include "tests/true_body.h"
#include "tracker/io/sequence_input.h"

namespace irbench {
namespace {
namespace fs = std::filesystem;
using irbench::testing::BodyMesh;
using irbench::testing::Inside;
using irbench::testing::Volume;

constexpr double kWideMarginPx = 4.1;

void CheckHulls(const std::string& avatar,
                const std::string& motion,
                const std::vector<int>& frames) {
  const fs::path dir = fs::temp_directory_path() / ("irbench_test_hull_loop_" + avatar);
  fs::remove_all(dir);
  fs::create_directories(dir);
  RenderJobOptions options;
  options.rig = "theater4";
  options.avatar = avatar;
  options.motion = motion;
  options.frames = frames.back() + 1;
  options.background_frames = 0;
  options.out = dir / "seq";
  const fs::path seq = RunRenderJob(options);
  const RenderInputs in = LoadRenderInputs(options);

  const SequenceInput input = SequenceInput::Open(seq);
  ASSERT_EQ(input.cameras().size(), 4u);
  const VoxelCarver carver(input.cameras());
  VoxelGridOptions wide;
  wide.margin_px = kWideMarginPx;
  const VoxelCarver wide_carver(input.cameras(), wide);
  std::mt19937 rng(11);
  for (int f : frames) {
    std::vector<cv::Mat> masks;
    std::vector<SilhouettePolygons> polys;
    for (const Camera& cam : input.cameras()) {
      char name[32];
      std::snprintf(name, sizeof(name), "%06d.png", f);
      masks.push_back(
          cv::imread((seq / "truth" / "masks" / cam.name / name).string(), cv::IMREAD_GRAYSCALE));
      ASSERT_FALSE(masks.back().empty());
      polys.push_back(ApproximateSilhouette(masks.back()));
    }
    const BodyMesh body = irbench::testing::PosedBody(in, f);
    const double true_volume = Volume(body);
    std::uniform_real_distribution<double> ux(body.lo.x(), body.hi.x()),
        uy(body.lo.y(), body.hi.y()), uz(body.lo.z(), body.hi.z());
    std::vector<Eigen::Vector3d> samples;
    while (samples.size() < 3000) {
      const Eigen::Vector3d p(ux(rng), uy(rng), uz(rng));
      if (Inside(body, p)) samples.push_back(p);
    }
    auto containment_of = [&](const VoxelHull& h) {
      int contained = 0;
      for (const Eigen::Vector3d& p : samples) contained += h.ContainsPoint(p);
      return double(contained) / samples.size();
    };
    const VoxelHull hull = carver.Carve(masks);
    if (std::getenv("IRBENCH_HULL_SWEEP")) {
      // Containment and volume against voxel size and margin (not asserted).
      for (double size : {0.02, 0.025, 0.03}) {
        for (double scale : {0.0, 0.5, 0.75, 1.0}) {
          for (double margin : {0.0, 0.5, 1.0}) {
            VoxelGridOptions o;
            o.voxel_size_m = size;
            o.footprint_scale = scale;
            o.margin_px = margin;
            const VoxelHull h = VoxelCarver(input.cameras(), o).Carve(masks);
            std::printf(
                "  voxel %.3f m, footprint scale %.2f, margin %.1f px: containment %.2f%%, volume "
                "ratio %.2f\n",
                size, scale, margin, 100 * containment_of(h), h.VolumeM3() / Volume(body));
          }
        }
      }
    }
    const double containment = containment_of(hull);
    const double ratio = hull.VolumeM3() / true_volume;

    const auto mesh = PolyhedralVisualHull(input.cameras(), polys);
    ASSERT_TRUE(mesh.has_value());
    // Douglas-Peucker polygons stay within epsilon of the contour pixel
    // centres (both ways), moved out by up to 1 px (the mitred offset): a
    // voxel hull with margin epsilon + 1.1 px holds every vertex.
    for (const auto& p : polys) ASSERT_LE(p.epsilon_px, kWideMarginPx - 1.1);
    const VoxelHull wide_hull = wide_carver.Carve(masks);
    int in_voxels = 0, in_wide = 0;
    for (const Eigen::Vector3d& v : mesh->vertices) {
      in_voxels += hull.ContainsPoint(v);
      in_wide += wide_hull.ContainsPoint(v);
    }
    const double vertices = double(mesh->vertices.size());
    const double poly_ratio = MeshVolume(*mesh) / true_volume;
    int edges[4];
    for (int c = 0; c < 4; ++c) edges[c] = polys[c].EdgeCount();
    std::printf(
        "%s %s frame %2d: true body %.4f m3, voxel hull %.4f m3 (%d voxels): containment %.2f%%, "
        "volume ratio %.2f; "
        "polyhedral hull ratio %.2f, %zu triangles, %.1f%% of its vertices in the voxel hull "
        "(%.2f%% with margin "
        "%.1f px); edges %d %d %d %d\n",
        avatar.c_str(), motion.c_str(), f, true_volume, hull.VolumeM3(), hull.occupied_count,
        100 * containment, ratio, poly_ratio, mesh->triangles.size(), 100.0 * in_voxels / vertices,
        100.0 * in_wide / vertices, wide.margin_px, edges[0], edges[1], edges[2], edges[3]);
    EXPECT_GE(containment, 0.98) << "frame " << f;
    EXPECT_LE(ratio, 2.0) << "frame " << f;
    EXPECT_GT(ratio, 1.0) << "frame " << f;
    // The polyhedral hull holds the body's volume and no more than the voxel
    // hull; its vertices lie in the voxel hull grown by the polygon tolerance.
    EXPECT_GT(poly_ratio, 1.0) << "frame " << f;
    EXPECT_LT(poly_ratio, ratio) << "frame " << f;
    EXPECT_GE(in_wide / vertices, 0.995) << "frame " << f;
    for (const int e : edges) {
      EXPECT_GE(e, 15) << "frame " << f;
      EXPECT_LE(e, 30) << "frame " << f;
    }
    if (f == frames[1]) {
      WriteVoxelCentersPly(dir / "voxels.ply", hull);
      WriteVoxelCubesPly(dir / "voxel_cubes.ply", hull);
      WriteMeshPly(dir / "polyhedral_hull.ply", *mesh);
      EXPECT_GT(fs::file_size(dir / "polyhedral_hull.ply"), 1000u);
    }
  }
  fs::remove_all(seq);
}

TEST(HullClosedLoopTest, VoxelHullContainsTheBodyWithBoundedVolume) {
  // The PLY files of the middle frame stay in $TMPDIR/irbench_test_hull_loop_<avatar>/.
  CheckHulls("p1", "flap_both", {0, 10, 20});
  CheckHulls("p4", "direct_traffic", {0, 12});
}

}  // namespace
}  // namespace irbench
