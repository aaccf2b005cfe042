// Cost of the sensor model per 320x240 camera-frame (issue 5: aim for <= 2 ms on
// 2 cores). Run: build/sensor_model_benchmark
#include <benchmark/benchmark.h>

#include "sim/sensor/sensor_model.h"

namespace irbench {
namespace {

void BM_SensorExposeAndTone(benchmark::State& state) {
  const SensorSetup setup = *SensorPreset("thesis");
  const SensorModel sensor(setup.sensor, 1, "cam0", 320, 240);
  cv::Mat radiance(240, 320, CV_32FC1);
  cv::randu(radiance, 0.0, 1.0);
  uint64_t frame = 0;
  for (auto _ : state) {
    cv::Mat out = sensor.ToOutput(sensor.Expose(radiance, 8.0, frame++));
    benchmark::DoNotOptimize(out.data);
  }
}
BENCHMARK(BM_SensorExposeAndTone)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace irbench
