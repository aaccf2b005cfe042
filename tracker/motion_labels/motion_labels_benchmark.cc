// Motion labelling's cost (thesis 7.1; issue 31 asks for ms per frame for
// both models and the training time): the online labeller per frame (both
// arms, the shipped window of 10 and 30 frames of history), and L-BFGS
// training on 2,000 synthetic frames of the model's size.
#include <benchmark/benchmark.h>

#include <random>

#include "tracker/motion_labels/motion_labeler.h"

namespace irbench {
namespace {

std::shared_ptr<MotionLabelModel> Model(int k) {
  auto m = std::make_shared<MotionLabelModel>();
  m->kind = k == 1 ? MotionModelKind::kCrf : MotionModelKind::kLdcrf;
  m->labels = {"REST", "PAUSE", "UP", "DOWN", "LEFT", "RIGHT", "FORWARD", "BACKWARD", "OTHER"};
  m->crf = LatentCrf(9, k, kMotionFeatureCount, 10);
  m->feature_mean = Eigen::VectorXd::Zero(kMotionFeatureCount);
  m->feature_scale = Eigen::VectorXd::Ones(kMotionFeatureCount);
  m->label_prior = Eigen::VectorXd::Constant(9, 1.0 / 9);
  std::mt19937_64 rng(1);
  std::normal_distribution<double> n(0, 0.1);
  Eigen::VectorXd theta(m->crf.ParameterCount());
  for (Eigen::Index i = 0; i < theta.size(); ++i) theta(i) = n(rng);
  m->crf.SetParameters(theta);
  return m;
}

MotionObservation Observation(int f, std::mt19937_64& rng) {
  std::normal_distribution<double> n(0, 0.05);
  MotionObservation o;
  o.t = f / 30.0;
  o.height_m = 1.75;
  o.waist = {0, 0, 1.0};
  o.neck = {0, 0, 1.45};
  for (int a = 0; a < 2; ++a) {
    o.shoulder[a] = {a == 0 ? 0.2 : -0.2, 0, 1.4};
    o.elbow[a] = o.shoulder[a] + Eigen::Vector3d(n(rng), n(rng), -0.3);
    o.wrist[a] = o.shoulder[a] + Eigen::Vector3d(n(rng), 0.2 + n(rng), -0.5);
  }
  return o;
}

void BM_MotionLabelerPerFrame(benchmark::State& state) {
  MotionLabeler labeler(Model(static_cast<int>(state.range(0))));
  std::mt19937_64 rng(2);
  int f = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(labeler.Update(f, Observation(f, rng)));
    ++f;
  }
}
BENCHMARK(BM_MotionLabelerPerFrame)->ArgName("states_per_label")->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond);

void BM_MotionLabelTraining(benchmark::State& state) {
  const int k = static_cast<int>(state.range(0));
  std::mt19937_64 rng(3);
  std::normal_distribution<double> n(0, 1);
  std::uniform_int_distribution<int> label(0, 8);
  std::vector<CrfSequence> data(4);
  for (CrfSequence& s : data) {
    s.features.resize(500, kMotionFeatureCount);
    int l = label(rng);
    for (int t = 0; t < 500; ++t) {
      if (t % 20 == 0) l = label(rng);
      for (int d = 0; d < kMotionFeatureCount; ++d) s.features(t, d) = n(rng) + (d == l ? 2.0 : 0.0);
      s.labels.push_back(l);
    }
  }
  CrfTrainingOptions options;
  options.max_iterations = 50;
  for (auto _ : state) {
    LatentCrf m(9, k, kMotionFeatureCount, 10);
    benchmark::DoNotOptimize(TrainCrf(&m, data, options));
  }
}
BENCHMARK(BM_MotionLabelTraining)->ArgName("states_per_label")->Arg(1)->Arg(2)->Unit(benchmark::kSecond)->Iterations(1);

}  // namespace
}  // namespace irbench
