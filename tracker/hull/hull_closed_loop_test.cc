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
#include "tracker/io/sequence_input.h"

namespace irbench {
namespace {
namespace fs = std::filesystem;

struct BodyMesh {
  std::vector<Eigen::Vector3d> v;
  std::vector<uint32_t> idx;
  Eigen::Vector3d lo, hi;
  // Triangles (first index) by the (y, z) cells of kCell their bounds touch.
  static constexpr double kCell = 0.05;
  int cells_y = 0, cells_z = 0;
  std::vector<std::vector<uint32_t>> buckets;

  int Cell(double value, double lo_value, int count) const {
    return std::clamp(static_cast<int>((value - lo_value) / kCell), 0, count - 1);
  }
  void Bucket() {
    cells_y = static_cast<int>((hi.y() - lo.y()) / kCell) + 1;
    cells_z = static_cast<int>((hi.z() - lo.z()) / kCell) + 1;
    buckets.assign(size_t(cells_y) * cells_z, {});
    for (uint32_t t = 0; t < idx.size(); t += 3) {
      const Eigen::Vector3d &a = v[idx[t]], &b = v[idx[t + 1]], &c = v[idx[t + 2]];
      const int y0 = Cell(std::min({a.y(), b.y(), c.y()}), lo.y(), cells_y);
      const int y1 = Cell(std::max({a.y(), b.y(), c.y()}), lo.y(), cells_y);
      const int z0 = Cell(std::min({a.z(), b.z(), c.z()}), lo.z(), cells_z);
      const int z1 = Cell(std::max({a.z(), b.z(), c.z()}), lo.z(), cells_z);
      for (int z = z0; z <= z1; ++z) {
        for (int y = y0; y <= y1; ++y) buckets[size_t(z) * cells_y + y].push_back(t);
      }
    }
  }
};

// Signed tetrahedra about the origin; the avatar is closed and outward wound.
double Volume(const BodyMesh& m) {
  double vol = 0;
  for (size_t t = 0; t < m.idx.size(); t += 3)
    vol += m.v[m.idx[t]].dot(m.v[m.idx[t + 1]].cross(m.v[m.idx[t + 2]]));
  return std::abs(vol) / 6.0;
}

// Ray parity along +x (crossings counted with a half-open rule on the
// triangle's projection onto the y-z plane, so shared edges count once).
bool Inside(const BodyMesh& m, const Eigen::Vector3d& p) {
  int crossings = 0;
  const auto& bucket = m.buckets[size_t(m.Cell(p.z(), m.lo.z(), m.cells_z)) * m.cells_y +
                                 m.Cell(p.y(), m.lo.y(), m.cells_y)];
  for (const uint32_t t : bucket) {
    const Eigen::Vector3d& a = m.v[m.idx[t]];
    const Eigen::Vector3d& b = m.v[m.idx[t + 1]];
    const Eigen::Vector3d& c = m.v[m.idx[t + 2]];
    if (std::max({a.x(), b.x(), c.x()}) < p.x()) continue;
    if (std::min({a.y(), b.y(), c.y()}) > p.y() || std::max({a.y(), b.y(), c.y()}) < p.y())
      continue;
    if (std::min({a.z(), b.z(), c.z()}) > p.z() || std::max({a.z(), b.z(), c.z()}) < p.z())
      continue;
    // Barycentric coordinates in the y-z plane.
    const double d = (b.y() - a.y()) * (c.z() - a.z()) - (c.y() - a.y()) * (b.z() - a.z());
    if (std::abs(d) < 1e-18) continue;
    const double w1 = ((p.y() - a.y()) * (c.z() - a.z()) - (c.y() - a.y()) * (p.z() - a.z())) / d;
    const double w2 = ((b.y() - a.y()) * (p.z() - a.z()) - (p.y() - a.y()) * (b.z() - a.z())) / d;
    const double w0 = 1 - w1 - w2;
    if (w0 < 0 || w1 < 0 || w2 < 0) continue;
    const double x = w0 * a.x() + w1 * b.x() + w2 * c.x();
    if (x > p.x()) ++crossings;
  }
  return crossings % 2 == 1;
}

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
    BodyMesh body;
    const JointTransforms fk = ForwardKinematics(in.avatar.skeleton, in.motion->At(f / in.fps));
    std::vector<MeshVertex> verts;
    SkinVertices(in.avatar, fk, verts);
    body.idx = in.avatar.indices;
    body.lo.setConstant(1e9);
    body.hi.setConstant(-1e9);
    for (const MeshVertex& v : verts) {
      body.v.push_back(v.position.cast<double>());
      body.lo = body.lo.cwiseMin(body.v.back());
      body.hi = body.hi.cwiseMax(body.v.back());
    }
    body.Bucket();
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
