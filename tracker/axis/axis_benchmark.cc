// 2D axis extraction (thesis 3.2) and body parts (3.3) on a 320x240 silhouette.

#include <benchmark/benchmark.h>

#include <opencv2/imgproc.hpp>

#include "tracker/axis/body_parts.h"

namespace irbench {
namespace {

cv::Mat1b Figure() {
  cv::Mat1b image(240, 320, uchar(0));
  cv::ellipse(image, {160, 130}, {22, 45}, 0, 0, 360, 255, cv::FILLED);
  cv::circle(image, {160, 58}, 12, 255, cv::FILLED);
  cv::line(image, {160, 68}, {160, 88}, 255, 10);
  cv::line(image, {150, 100}, {95, 40}, 255, 8);
  cv::line(image, {170, 100}, {255, 100}, 255, 8);
  cv::line(image, {150, 165}, {140, 228}, 255, 14);
  cv::line(image, {170, 165}, {180, 228}, 255, 14);
  return image;
}

void BM_ExtractAxisPoints(benchmark::State& state) {
  const cv::Mat1b image = Figure();
  for (auto _ : state) benchmark::DoNotOptimize(ExtractAxisPoints(image));
}
BENCHMARK(BM_ExtractAxisPoints)->Unit(benchmark::kMicrosecond);

void BM_AxisPointsAndBodyParts(benchmark::State& state) {
  const cv::Mat1b image = Figure();
  for (auto _ : state) {
    const AxisGraph graph = ExtractAxisPoints(image);
    benchmark::DoNotOptimize(SegmentBodyParts(image, graph));
  }
}
BENCHMARK(BM_AxisPointsAndBodyParts)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace irbench
