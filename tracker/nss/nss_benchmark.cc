// The NSS skeleton's cost (thesis 4.4.1) on a voxelised stick figure at 2 cm
// (about 9,000 voxels, a person's hull at the tracker's default voxel size)
// and 3 cm, by the number of Isomap landmarks.
#include <benchmark/benchmark.h>

#include "tracker/nss/nss_skeleton.h"
#include "tracker/nss/stick_figure.h"

namespace irbench {
namespace {

void BM_NssSkeleton(benchmark::State& state) {
  const testing::StickFigure figure = testing::MakeStickFigure(
      {0.45, 0, 1.55}, {0.65, 0, 1.75}, {-0.3, 0.1, 1.15}, {-0.26, 0.37, 1.15}, state.range(0) / 100.0);
  NssOptions options;
  options.landmarks = static_cast<int>(state.range(1));
  for (auto _ : state) benchmark::DoNotOptimize(ComputeNssSkeleton(figure.hull, {0, 1}, options));
  state.counters["voxels"] = figure.hull.occupied_count;
}
BENCHMARK(BM_NssSkeleton)->Args({2, 48})->Args({2, 24})->Args({3, 48})->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace irbench
