#include "tracker/gesture/hmm.h"

#include <gtest/gtest.h>

#include <Eigen/LU>

#include <cmath>
#include <functional>
#include <limits>
#include <random>

namespace irbench {
namespace {

constexpr double kTol = 1e-9;

Eigen::VectorXd RandomDistribution(int n, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(0.05, 1.0);
  Eigen::VectorXd p(n);
  for (int i = 0; i < n; ++i) p(i) = u(rng);
  return p / p.sum();
}

LogMarkovChain RandomChain(int n, std::mt19937_64& rng) {
  Eigen::MatrixXd a(n, n);
  for (int i = 0; i < n; ++i) a.row(i) = RandomDistribution(n, rng).transpose();
  return LogMarkovChain::FromProbabilities(RandomDistribution(n, rng), a);
}

Eigen::MatrixXd RandomLogEmission(int t_count, int n, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(-6.0, 0.0);
  Eigen::MatrixXd e(t_count, n);
  for (int t = 0; t < t_count; ++t) {
    for (int j = 0; j < n; ++j) e(t, j) = u(rng);
  }
  return e;
}

// Every state path of length T, by brute force: the joint log-probability of
// each, visited in order.
void ForEachPath(const LogMarkovChain& chain, const Eigen::MatrixXd& e,
                 const std::function<void(const std::vector<int>&, double)>& visit) {
  const int t_count = static_cast<int>(e.rows()), n = chain.size();
  std::vector<int> path(t_count, 0);
  while (true) {
    double lp = chain.log_initial(path[0]) + e(0, path[0]);
    for (int t = 1; t < t_count; ++t) lp += chain.log_transition(path[t - 1], path[t]) + e(t, path[t]);
    visit(path, lp);
    int t = t_count - 1;
    while (t >= 0 && ++path[t] == n) path[t--] = 0;
    if (t < 0) break;
  }
}

TEST(LogSumExp, HandlesMinusInfinityAndLargeValues) {
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_EQ(LogSumExp(Eigen::VectorXd::Constant(3, -inf)), -inf);
  EXPECT_EQ(LogSumExp(Eigen::VectorXd()), -inf);
  Eigen::VectorXd v(3);
  v << -inf, 1000, 1000;
  EXPECT_NEAR(LogSumExp(v), 1000 + std::log(2.0), 1e-12);
  v << -2000, -2000, -inf;
  EXPECT_NEAR(LogSumExp(v), -2000 + std::log(2.0), 1e-12);
}

// Forward, backward, posteriors and Viterbi against enumeration of all N^T
// paths, for chains of length 1 to 6.
TEST(Hmm, RecursionsMatchBruteForceEnumeration) {
  std::mt19937_64 rng(7);
  for (int t_count = 1; t_count <= 6; ++t_count) {
    for (int n : {2, 3}) {
      const LogMarkovChain chain = RandomChain(n, rng);
      const Eigen::MatrixXd e = RandomLogEmission(t_count, n, rng);
      std::vector<double> log_probs;
      Eigen::MatrixXd gamma = Eigen::MatrixXd::Zero(t_count, n);
      Eigen::MatrixXd xi = Eigen::MatrixXd::Zero(n, n);
      std::vector<int> best_path;
      double best = -std::numeric_limits<double>::infinity();
      ForEachPath(chain, e, [&](const std::vector<int>& path, double lp) {
        log_probs.push_back(lp);
        if (lp > best) best = lp, best_path = path;
      });
      const double ll = LogSumExp(Eigen::Map<Eigen::VectorXd>(log_probs.data(), log_probs.size()));
      ForEachPath(chain, e, [&](const std::vector<int>& path, double lp) {
        const double w = std::exp(lp - ll);
        for (int t = 0; t < t_count; ++t) gamma(t, path[t]) += w;
        for (int t = 0; t + 1 < t_count; ++t) xi(path[t], path[t + 1]) += w;
      });

      EXPECT_NEAR(LogForward(chain, e), ll, kTol);
      const Posteriors p = ForwardBackward(chain, e);
      EXPECT_NEAR(p.log_likelihood, ll, kTol);
      EXPECT_LT((p.gamma - gamma).cwiseAbs().maxCoeff(), kTol) << "T=" << t_count << " N=" << n;
      EXPECT_LT((p.xi_sum - xi).cwiseAbs().maxCoeff(), kTol) << "T=" << t_count << " N=" << n;
      // The backward pass gives the same likelihood from the first frame.
      const Eigen::VectorXd first = chain.log_initial + e.row(0).transpose() + p.log_beta.row(0).transpose();
      EXPECT_NEAR(LogSumExp(first), ll, kTol);
      double viterbi_lp = 0;
      EXPECT_EQ(Viterbi(chain, e, &viterbi_lp), best_path) << "T=" << t_count << " N=" << n;
      EXPECT_NEAR(viterbi_lp, best, kTol);
    }
  }
}

// A long sequence whose probability underflows doubles a thousand times over
// still gives a finite log-likelihood, the sum of the per-frame ones for a
// chain that cannot leave its state.
TEST(Hmm, LongSequencesDoNotUnderflow) {
  Eigen::MatrixXd a = Eigen::MatrixXd::Identity(2, 2);
  const LogMarkovChain chain = LogMarkovChain::FromProbabilities(Eigen::Vector2d(1, 0), a);
  const int t_count = 100000;
  Eigen::MatrixXd e = Eigen::MatrixXd::Constant(t_count, 2, -3.0);
  const Posteriors p = ForwardBackward(chain, e);
  EXPECT_NEAR(p.log_likelihood, -3.0 * t_count, 1e-6);
  EXPECT_NEAR(p.gamma(t_count - 1, 0), 1.0, 1e-12);
  EXPECT_LT(p.gamma(t_count - 1, 1), 1e-300);  // Eigen's vector exp gives a denormal for -inf
  double lp = 0;
  const std::vector<int> path = Viterbi(chain, e, &lp);
  EXPECT_EQ(path.back(), 0);
  EXPECT_NEAR(lp, -3.0 * t_count, 1e-6);
}

TEST(Hmm, ImpossibleSequencesAreReportedNotNaN) {
  const LogMarkovChain chain =
      LogMarkovChain::FromProbabilities(Eigen::Vector2d(1, 0), Eigen::Matrix2d::Identity());
  DiscreteHmm hmm{chain, Eigen::MatrixXd()};
  hmm.log_emission = Eigen::Matrix2d::Identity().unaryExpr([](double p) { return p > 0 ? 0.0 : -INFINITY; });
  EXPECT_EQ(hmm.LogLikelihood({0, 1}), -std::numeric_limits<double>::infinity());
  EXPECT_THROW(ForwardBackward(chain, hmm.EmissionLogLikelihoods({0, 1})), std::domain_error);
  EXPECT_THROW(hmm.EmissionLogLikelihoods({2}), std::out_of_range);
}

// Samples a discrete HMM (for training tests).
std::vector<int> Sample(const DiscreteHmm& hmm, int t_count, std::mt19937_64& rng) {
  auto draw = [&](const Eigen::VectorXd& log_p) {
    std::uniform_real_distribution<double> u(0, 1);
    double x = u(rng);
    for (int i = 0; i < log_p.size(); ++i) {
      x -= std::exp(log_p(i));
      if (x <= 0) return i;
    }
    return static_cast<int>(log_p.size()) - 1;
  };
  std::vector<int> y;
  int q = draw(hmm.chain.log_initial);
  for (int t = 0; t < t_count; ++t) {
    y.push_back(draw(hmm.log_emission.row(q).transpose()));
    q = draw(hmm.chain.log_transition.row(q).transpose());
  }
  return y;
}

// EM never lowers the likelihood (maximum likelihood, no pseudo-counts), and
// it ends above the starting point.
TEST(Hmm, DiscreteBaumWelchNeverLowersTheLikelihood) {
  std::mt19937_64 rng(11);
  DiscreteHmm truth;
  truth.chain = LogMarkovChain::FromProbabilities(Eigen::Vector3d(0.8, 0.1, 0.1),
                                                 (Eigen::Matrix3d() << 0.9, 0.08, 0.02,  //
                                                  0.05, 0.9, 0.05,                       //
                                                  0.02, 0.08, 0.9)
                                                     .finished());
  truth.log_emission = (Eigen::MatrixXd(3, 4) << 0.7, 0.1, 0.1, 0.1,  //
                        0.1, 0.7, 0.1, 0.1,                            //
                        0.05, 0.05, 0.2, 0.7)
                           .finished()
                           .array()
                           .log();
  std::vector<std::vector<int>> data;
  for (int s = 0; s < 6; ++s) data.push_back(Sample(truth, 120, rng));
  DiscreteHmm model;
  model.chain = RandomChain(3, rng);
  Eigen::MatrixXd b(3, 4);
  for (int j = 0; j < 3; ++j) b.row(j) = RandomDistribution(4, rng).transpose();
  model.log_emission = b.array().log();
  BaumWelchOptions options;
  options.max_iterations = 60;
  options.tolerance_per_frame = 0;
  const TrainingTrace trace = TrainDiscreteHmm(data, options, &model);
  ASSERT_EQ(trace.iterations, 60);
  for (size_t i = 1; i < trace.log_likelihood.size(); ++i) {
    EXPECT_GE(trace.log_likelihood[i], trace.log_likelihood[i - 1] - 1e-9) << "iteration " << i;
  }
  EXPECT_GE(trace.final_log_likelihood, trace.log_likelihood.back() - 1e-9);
  EXPECT_GT(trace.final_log_likelihood, trace.log_likelihood.front() + 10);
  model.chain.Check();
  // Started from the model that made the data, EM ends at least as high as
  // that model (the maximum-likelihood estimate explains its data better).
  double truth_ll = 0;
  for (const auto& y : data) truth_ll += truth.LogLikelihood(y);
  DiscreteHmm from_truth = truth;
  const TrainingTrace from_truth_trace = TrainDiscreteHmm(data, options, &from_truth);
  EXPECT_NEAR(from_truth_trace.log_likelihood.front(), truth_ll, 1e-9 * std::abs(truth_ll));
  EXPECT_GT(from_truth_trace.final_log_likelihood, truth_ll);
}

TEST(Hmm, GaussianDensityMatchesTheFormula) {
  Eigen::MatrixXd cov(2, 2);
  cov << 2.0, 0.6, 0.6, 1.0;
  Eigen::MatrixXd mean(2, 1);
  mean << 0.5, -1.0;
  Eigen::MatrixXd y(2, 1);
  y << 1.5, 0.25;
  const Eigen::Vector2d r = y.col(0) - mean.col(0);
  const double expected =
      -0.5 * (2 * std::log(2 * M_PI) + std::log(cov.determinant()) + r.dot(cov.inverse() * r));
  EXPECT_NEAR(GaussianLogDensities(y, mean, cov)(0, 0), expected, 1e-12);
  EXPECT_THROW(GaussianLogDensities(y, mean, -cov), std::domain_error);
}

TEST(Hmm, GaussianBaumWelchNeverLowersTheLikelihoodAndFindsTheMeans) {
  std::mt19937_64 rng(3);
  std::normal_distribution<double> noise(0, 0.3);
  // Two states, means (0, 0) and (2, 1), switching rarely.
  std::vector<Eigen::MatrixXd> data;
  for (int s = 0; s < 4; ++s) {
    Eigen::MatrixXd y(2, 200);
    int q = s % 2;
    for (int t = 0; t < 200; ++t) {
      if (t % 50 == 49) q = 1 - q;
      y(0, t) = 2.0 * q + noise(rng);
      y(1, t) = 1.0 * q + noise(rng);
    }
    data.push_back(y);
  }
  GaussianHmm model;
  model.chain = StickyChain(2, 0.9);
  model.means = (Eigen::MatrixXd(2, 2) << 0.5, 1.0, 0.0, 0.8).finished();
  model.covariance = Eigen::Matrix2d::Identity();
  BaumWelchOptions options;
  options.tolerance_per_frame = 0;
  options.max_iterations = 30;
  const TrainingTrace trace = TrainGaussianHmm(data, options, {}, &model);
  for (size_t i = 1; i < trace.log_likelihood.size(); ++i) {
    EXPECT_GE(trace.log_likelihood[i], trace.log_likelihood[i - 1] - 1e-9) << "iteration " << i;
  }
  const int hi = model.means(0, 0) > model.means(0, 1) ? 0 : 1;
  EXPECT_NEAR(model.means(0, hi), 2.0, 0.05);
  EXPECT_NEAR(model.means(1, hi), 1.0, 0.05);
  EXPECT_NEAR(model.means(0, 1 - hi), 0.0, 0.05);
  EXPECT_NEAR(model.covariance(0, 0), 0.09, 0.015);
  EXPECT_NEAR(std::exp(model.chain.log_transition(0, 0)), 0.98, 0.015);
}

}  // namespace
}  // namespace irbench
