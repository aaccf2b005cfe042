#include "tracker/motion_labels/latent_crf.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <random>

namespace irbench {
namespace {

LatentCrf RandomModel(int labels, int k, int dims, int window, uint64_t seed) {
  LatentCrf m(labels, k, dims, window);
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> n(0, 0.7);
  Eigen::VectorXd theta(m.ParameterCount());
  for (Eigen::Index i = 0; i < theta.size(); ++i) theta(i) = n(rng);
  m.SetParameters(theta);
  return m;
}

CrfSequence RandomSequence(int t_count, int dims, int labels, std::mt19937_64& rng) {
  std::normal_distribution<double> n(0, 1);
  std::uniform_int_distribution<int> l(0, labels - 1);
  CrfSequence s;
  s.features.resize(t_count, dims);
  for (int t = 0; t < t_count; ++t) {
    for (int d = 0; d < dims; ++d) s.features(t, d) = n(rng);
    s.labels.push_back(l(rng));
  }
  return s;
}

// Calls f with every hidden path of length t_count over n states.
void ForEachPath(int t_count, int n, const std::function<void(const std::vector<int>&)>& f) {
  std::vector<int> h(t_count, 0);
  while (true) {
    f(h);
    int i = 0;
    while (i < t_count && ++h[i] == n) h[i++] = 0;
    if (i == t_count) return;
  }
}

double PathScore(const LatentCrf& m, const Eigen::MatrixXd& potentials, const std::vector<int>& h) {
  double s = 0;
  for (size_t t = 0; t < h.size(); ++t) {
    s += potentials(static_cast<Eigen::Index>(t), h[t]);
    if (t > 0) s += m.transition()(h[t - 1], h[t]);
  }
  return s;
}

// Label marginals and p(y | x) by enumerating every hidden path.
TEST(LatentCrfTest, MarginalsAndLikelihoodMatchBruteForce) {
  std::mt19937_64 rng(7);
  for (int k : {1, 2}) {
    for (int t_count : {1, 3, 5}) {
      const LatentCrf m = RandomModel(3, k, 2, 1, 11 + k);
      const CrfSequence s = RandomSequence(t_count, 2, 3, rng);
      const Eigen::MatrixXd potentials = m.StatePotentials(s.features);
      Eigen::MatrixXd marginals = Eigen::MatrixXd::Zero(t_count, 3);
      double z = 0, z_y = 0;
      ForEachPath(t_count, m.states(), [&](const std::vector<int>& h) {
        const double p = std::exp(PathScore(m, potentials, h));
        z += p;
        bool fits = true;
        for (int t = 0; t < t_count; ++t) {
          marginals(t, m.LabelOf(h[t])) += p;
          fits = fits && m.LabelOf(h[t]) == s.labels[t];
        }
        if (fits) z_y += p;
      });
      marginals /= z;
      const Eigen::MatrixXd got = m.LabelMarginals(s.features);
      ASSERT_EQ(got.rows(), t_count);
      EXPECT_LT((got - marginals).cwiseAbs().maxCoeff(), 1e-10) << "k " << k << " T " << t_count;
      // The objective without regularisation is -log p(y | x).
      EXPECT_NEAR(CrfObjective(m, {s}, 0, nullptr), -std::log(z_y / z), 1e-9);
    }
  }
}

// The analytic gradient against central differences, for the CRF and the
// LDCRF, with the regulariser.
TEST(LatentCrfTest, GradientMatchesFiniteDifferences) {
  std::mt19937_64 rng(3);
  for (int k : {1, 2}) {
    LatentCrf m = RandomModel(3, k, 2, 1, 5 + k);
    const std::vector<CrfSequence> data = {RandomSequence(6, 2, 3, rng), RandomSequence(4, 2, 3, rng)};
    Eigen::VectorXd gradient;
    CrfObjective(m, data, 0.5, &gradient);
    const Eigen::VectorXd theta = m.Parameters();
    const double h = 1e-5;
    for (Eigen::Index i = 0; i < theta.size(); ++i) {
      Eigen::VectorXd plus = theta, minus = theta;
      plus(i) += h;
      minus(i) -= h;
      m.SetParameters(plus);
      const double f_plus = CrfObjective(m, data, 0.5, nullptr);
      m.SetParameters(minus);
      const double f_minus = CrfObjective(m, data, 0.5, nullptr);
      EXPECT_NEAR(gradient(i), (f_plus - f_minus) / (2 * h), 1e-6 * (1 + std::abs(gradient(i)))) << "k " << k << " i " << i;
    }
    m.SetParameters(theta);
  }
}

// With one hidden state per label the LDCRF's restricted forward-backward
// numerator equals the CRF's labelled-path score: same objective, same
// gradient.
TEST(LatentCrfTest, LdcrfWithOneStatePerLabelEqualsCrf) {
  std::mt19937_64 rng(9);
  const LatentCrf m = RandomModel(4, 1, 3, 2, 21);
  const std::vector<CrfSequence> data = {RandomSequence(30, 3, 4, rng), RandomSequence(12, 3, 4, rng)};
  Eigen::VectorXd g_crf, g_ldcrf;
  const double f_crf = CrfObjective(m, data, 0.5, &g_crf, CrfNumerator::kPath);
  const double f_ldcrf = CrfObjective(m, data, 0.5, &g_ldcrf, CrfNumerator::kRestricted);
  EXPECT_NEAR(f_crf, f_ldcrf, 1e-9 * std::abs(f_crf));
  EXPECT_LT((g_crf - g_ldcrf).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_THROW(CrfObjective(RandomModel(4, 2, 3, 2, 1), data, 0.5, nullptr, CrfNumerator::kPath),
               std::invalid_argument);
}

// Two labels that differ only in where the feature goes next (up for label
// 1, down for 0, the same values overall): a frame alone cannot tell them
// apart, its window can. Trained CRF and LDCRF label held-out chains.
std::vector<CrfSequence> DirectionData(int count, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0, 0.05);
  std::uniform_int_distribution<int> run(8, 20);
  std::vector<CrfSequence> out;
  for (int c = 0; c < count; ++c) {
    CrfSequence s;
    std::vector<double> x;
    double v = 0;
    int label = c % 2;
    while (x.size() < 120) {
      const int n = run(rng);
      for (int i = 0; i < n; ++i) {
        v += label ? 0.1 : -0.1;
        x.push_back(v);
        s.labels.push_back(label);
      }
      label = 1 - label;
    }
    s.features.resize(static_cast<Eigen::Index>(x.size()), 1);
    for (size_t t = 0; t < x.size(); ++t) s.features(static_cast<Eigen::Index>(t), 0) = x[t] + noise(rng);
    out.push_back(s);
  }
  return out;
}

double Accuracy(const LatentCrf& m, const std::vector<CrfSequence>& data) {
  int right = 0, total = 0;
  for (const CrfSequence& s : data) {
    const std::vector<int> y = m.Decode(s.features);
    for (size_t t = 0; t < y.size(); ++t) right += y[t] == s.labels[t];
    total += static_cast<int>(y.size());
  }
  return double(right) / total;
}

TEST(LatentCrfTest, TrainingLearnsFromTheWindowAndIsDeterministic) {
  const std::vector<CrfSequence> train = DirectionData(6, 1), test = DirectionData(4, 2);
  for (int k : {1, 2}) {
    LatentCrf m(2, k, 1, 2);
    CrfTrainingOptions o;
    o.sigma = 2;
    int calls = 0;
    o.progress = [&](int, double) { ++calls; };
    const double before = CrfObjective(m, train, o.sigma, nullptr);
    const CrfTrainingReport r = TrainCrf(&m, train, o);
    EXPECT_LT(r.objective, 0.3 * before) << r.status_text;
    EXPECT_EQ(calls, r.iterations);
    EXPECT_GT(Accuracy(m, test), 0.9) << "k " << k;
    LatentCrf again(2, k, 1, 2);
    TrainCrf(&again, train, o);
    EXPECT_EQ(again.Parameters(), m.Parameters());
  }
}

TEST(LatentCrfTest, RejectsBadInput) {
  EXPECT_THROW(LatentCrf(0, 1, 1, 0), std::invalid_argument);
  LatentCrf m(2, 1, 2, 1);
  CrfSequence s;
  s.features = Eigen::MatrixXd::Zero(3, 2);
  s.labels = {0, 1, 2};
  EXPECT_THROW(CrfObjective(m, {s}, 0.5, nullptr), std::invalid_argument);
  s.labels = {0, 1};
  EXPECT_THROW(CrfObjective(m, {s}, 0.5, nullptr), std::invalid_argument);
  CrfTrainingOptions o;
  o.sigma = -1;
  EXPECT_THROW(o.Check(), std::invalid_argument);
}

}  // namespace
}  // namespace irbench
