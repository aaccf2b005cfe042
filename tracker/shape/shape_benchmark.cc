// The shape descriptor's cost on a body-sized point cloud (thesis 4.3; the
// issue's aim: descriptor, matching pursuit and gesture update in 3 ms).
#include <benchmark/benchmark.h>

#include <random>

#include "tracker/shape/shape_descriptor.h"

namespace irbench {
namespace {

std::vector<Eigen::Vector3d> BodyCloud(int n) {
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> u(-1, 1), z(0, 1.75);
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < n; ++i) points.emplace_back(0.2 * u(rng), 0.12 * u(rng), z(rng));
  return points;
}

void BM_ShapeDescriptor(benchmark::State& state) {
  const auto points = BodyCloud(static_cast<int>(state.range(0)));
  ShapeDescriptorOptions options;
  options.max_points = static_cast<int>(state.range(0));
  for (auto _ : state) benchmark::DoNotOptimize(ComputeShapeDescriptor(points, 1.75, options));
}
BENCHMARK(BM_ShapeDescriptor)->Arg(500)->Arg(1000)->Arg(1500)->Arg(3000)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace irbench
