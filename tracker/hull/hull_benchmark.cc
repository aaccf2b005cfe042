// Voxel carving and the polyhedral hull for 4 cameras at 320 x 240 (theater4
// layout) on an analytic body-sized solid: a capsule-ish stack of spheres.

#include <benchmark/benchmark.h>

#include "tracker/hull/hull_test_util.h"
#include "tracker/hull/polyhedral_hull.h"
#include "tracker/hull/voxel_hull.h"

namespace irbench {
namespace {

std::vector<Camera> Theater4() {
  std::vector<Camera> cams;
  const Eigen::Vector3d positions[4] = {
      {-1.3, 3.7, 0.75}, {1.3, 3.7, 0.75}, {0.0, 0.3, 4.0}, {-3.6, 0.4, 1.9}};
  const Eigen::Vector3d targets[4] = {{0, 0, 1}, {0, 0, 1}, {0, 0, 0}, {0, 0, 1}};
  for (int i = 0; i < 4; ++i) {
    Camera cam;
    cam.fx = cam.fy = i == 2 ? 170 : 260;
    cam.cx = 160;
    cam.cy = 120;
    cam.dist = {-0.1, 0.03, 0, 0, 0};
    cam.cam_from_world = *LookAt(positions[i], targets[i],
                                 i == 2 ? Eigen::Vector3d::UnitY() : Eigen::Vector3d::UnitZ());
    cams.push_back(cam);
  }
  return cams;
}

// A person-sized solid: spheres of 0.15 m radius from the floor to 1.7 m.
std::vector<cv::Mat> BodySilhouettes(const std::vector<Camera>& cams) {
  std::vector<cv::Mat> out;
  for (const Camera& cam : cams) {
    cv::Mat mask = cv::Mat::zeros(cam.height, cam.width, CV_8UC1);
    for (double z = 0.15; z <= 1.6; z += 0.1) {
      mask |= irbench::testing::SphereSilhouette(cam, {0.1, 0.2, z}, 0.15);
    }
    out.push_back(mask);
  }
  return out;
}

void BM_VoxelCarve(benchmark::State& state) {
  const std::vector<Camera> cams = Theater4();
  VoxelGridOptions options;
  options.voxel_size_m = state.range(0) / 1000.0;
  const VoxelCarver carver(cams, options);
  const std::vector<cv::Mat> sil = BodySilhouettes(cams);
  int occupied = 0;
  for (auto _ : state) {
    const VoxelHull hull = carver.Carve(sil);
    occupied = hull.occupied_count;
    benchmark::DoNotOptimize(occupied);
  }
  state.counters["voxels"] = double(size_t(carver.nx()) * carver.ny() * carver.nz());
  state.counters["candidates"] = double(carver.candidate_count());
  state.counters["occupied"] = occupied;
}
BENCHMARK(BM_VoxelCarve)->Arg(20)->Arg(25)->Arg(30)->Unit(benchmark::kMillisecond);

// Tolerant carving (max_missing_views 1): a block must be certainly outside
// two views before it is skipped whole.
void BM_VoxelCarveTolerant(benchmark::State& state) {
  const std::vector<Camera> cams = Theater4();
  VoxelGridOptions options;
  options.max_missing_views = 1;
  const VoxelCarver carver(cams, options);
  const std::vector<cv::Mat> sil = BodySilhouettes(cams);
  int occupied = 0;
  for (auto _ : state) {
    occupied = carver.Carve(sil).occupied_count;
    benchmark::DoNotOptimize(occupied);
  }
  state.counters["occupied"] = occupied;
}
BENCHMARK(BM_VoxelCarveTolerant)->Unit(benchmark::kMillisecond);

void BM_VoxelLookUpTable(benchmark::State& state) {
  const std::vector<Camera> cams = Theater4();
  VoxelGridOptions options;
  options.voxel_size_m = 0.025;
  for (auto _ : state) {
    const VoxelCarver carver(cams, options);
    benchmark::DoNotOptimize(carver.candidate_count());
  }
}
BENCHMARK(BM_VoxelLookUpTable)->Unit(benchmark::kMillisecond)->Iterations(2);

void BM_PolyhedralHull(benchmark::State& state) {
  const std::vector<Camera> cams = Theater4();
  std::vector<SilhouettePolygons> polys;
  for (const cv::Mat& m : BodySilhouettes(cams)) polys.push_back(ApproximateSilhouette(m));
  size_t triangles = 0;
  for (auto _ : state) {
    const auto mesh = PolyhedralVisualHull(cams, polys);
    triangles = mesh ? mesh->triangles.size() : 0;
    benchmark::DoNotOptimize(triangles);
  }
  state.counters["triangles"] = double(triangles);
}
BENCHMARK(BM_PolyhedralHull)->Unit(benchmark::kMillisecond);

void BM_Polygons(benchmark::State& state) {
  const std::vector<Camera> cams = Theater4();
  const std::vector<cv::Mat> sil = BodySilhouettes(cams);
  for (auto _ : state) {
    for (const cv::Mat& m : sil) benchmark::DoNotOptimize(ApproximateSilhouette(m).EdgeCount());
  }
}
BENCHMARK(BM_Polygons)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace irbench
