#include "tracker/gesture/fhmm.h"

#include <gtest/gtest.h>

#include <Eigen/Cholesky>

#include <cmath>
#include <random>

namespace irbench {
namespace {

// An FHMM drawn at random: chains with distinct sticky dynamics, weights
// apart, a correlated covariance.
Fhmm RandomFhmm(int chains, int k, int d, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(0.05, 1.0), w(-2.0, 2.0);
  Fhmm f;
  for (int m = 0; m < chains; ++m) {
    Eigen::MatrixXd a(k, k);
    for (int i = 0; i < k; ++i) {
      for (int j = 0; j < k; ++j) a(i, j) = u(rng) + (i == j ? 3.0 : 0.0);
      a.row(i) /= a.row(i).sum();
    }
    Eigen::VectorXd pi(k);
    for (int i = 0; i < k; ++i) pi(i) = u(rng);
    f.chains.push_back(LogMarkovChain::FromProbabilities(pi / pi.sum(), a));
    Eigen::MatrixXd weights(d, k);
    for (int i = 0; i < d; ++i) {
      for (int j = 0; j < k; ++j) weights(i, j) = w(rng);
    }
    f.weights.push_back(weights);
  }
  Eigen::MatrixXd c(d, d);
  for (int i = 0; i < d; ++i) {
    for (int j = 0; j < d; ++j) c(i, j) = w(rng);
  }
  f.covariance = 0.05 * c * c.transpose() + 0.1 * Eigen::MatrixXd::Identity(d, d);
  return f;
}

// Samples T frames of `f`.
Eigen::MatrixXd Sample(const Fhmm& f, int t_count, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(0, 1);
  std::normal_distribution<double> z(0, 1);
  auto draw = [&](const Eigen::VectorXd& log_p) {
    double x = u(rng);
    for (int i = 0; i < log_p.size(); ++i) {
      x -= std::exp(log_p(i));
      if (x <= 0) return i;
    }
    return static_cast<int>(log_p.size()) - 1;
  };
  const Eigen::MatrixXd l = f.covariance.llt().matrixL();
  std::vector<int> q(f.chain_count());
  for (int m = 0; m < f.chain_count(); ++m) q[m] = draw(f.chains[m].log_initial);
  Eigen::MatrixXd y(f.dimension(), t_count);
  for (int t = 0; t < t_count; ++t) {
    Eigen::VectorXd noise(f.dimension());
    for (int i = 0; i < f.dimension(); ++i) noise(i) = z(rng);
    y.col(t) = l * noise;
    for (int m = 0; m < f.chain_count(); ++m) {
      y.col(t) += f.weights[m].col(q[m]);
      q[m] = draw(f.chains[m].log_transition.row(q[m]).transpose());
    }
  }
  return y;
}

// The factored forward recursion gives exactly the likelihood and the
// alphas of the flat HMM over the K^M product states.
TEST(Fhmm, ExactInferenceEqualsTheFlatProductHmm) {
  std::mt19937_64 rng(5);
  for (int chains : {1, 2, 3}) {
    const Fhmm f = RandomFhmm(chains, chains == 3 ? 3 : 5, 4, rng);
    f.Check();
    const LogMarkovChain flat = f.ProductChain();
    flat.Check();
    ASSERT_EQ(flat.size(), f.product_size());
    const Eigen::MatrixXd y = Sample(f, 40, rng);
    Eigen::MatrixXd flat_alpha;
    const double flat_ll = LogForward(flat, f.EmissionLogLikelihoods(y), &flat_alpha);
    EXPECT_NEAR(f.LogLikelihood(y), flat_ll, 1e-9 * std::abs(flat_ll)) << chains << " chains";
    EXPECT_LT((f.LogAlpha(y) - flat_alpha).cwiseAbs().maxCoeff(), 1e-8) << chains << " chains";
  }
}

TEST(Fhmm, ProductStatesEnumerateTheChainsStates) {
  std::mt19937_64 rng(1);
  const Fhmm f = RandomFhmm(2, 5, 5, rng);
  EXPECT_EQ(f.product_size(), 25);
  EXPECT_EQ(f.StatesOf(0), (std::vector<int>{0, 0}));
  EXPECT_EQ(f.StatesOf(7), (std::vector<int>{2, 1}));
  EXPECT_EQ(f.StatesOf(24), (std::vector<int>{4, 4}));
  // The product mean of state (2, 1) is W_0 column 2 plus W_1 column 1.
  EXPECT_LT((f.ProductMeans().col(7) - f.weights[0].col(2) - f.weights[1].col(1)).norm(), 1e-12);
}

// EM never lowers the likelihood; from a seeded start it finds a model that
// explains held-out data nearly as well as the one that made it (EM finds a
// local maximum); from the true model it ends above the truth's likelihood.
TEST(Fhmm, ExactEmNeverLowersTheLikelihood) {
  std::mt19937_64 rng(9);
  const Fhmm truth = RandomFhmm(2, 3, 4, rng);
  std::vector<Eigen::MatrixXd> train, test;
  for (int s = 0; s < 5; ++s) train.push_back(Sample(truth, 150, rng));
  for (int s = 0; s < 3; ++s) test.push_back(Sample(truth, 150, rng));
  Fhmm model = InitialFhmm(train, 2, 3, 0.8, 42);
  BaumWelchOptions options;
  options.max_iterations = 40;
  options.tolerance_per_frame = 0;
  const TrainingTrace trace = TrainFhmm(train, options, {}, &model);
  ASSERT_GE(trace.log_likelihood.size(), 10u);
  for (size_t i = 1; i < trace.log_likelihood.size(); ++i) {
    EXPECT_GE(trace.log_likelihood[i], trace.log_likelihood[i - 1] - 1e-7 * std::abs(trace.log_likelihood[i]))
        << "iteration " << i;
  }
  double ll_model = 0, ll_truth = 0;
  for (const auto& y : test) ll_model += model.LogLikelihood(y), ll_truth += truth.LogLikelihood(y);
  const double frames = 3 * 150;
  EXPECT_GT(ll_model / frames, ll_truth / frames - 0.3) << "model " << ll_model << " truth " << ll_truth;
  Fhmm from_truth = truth;
  options.max_iterations = 10;
  const TrainingTrace from_truth_trace = TrainFhmm(train, options, {}, &from_truth);
  EXPECT_GT(from_truth_trace.final_log_likelihood, from_truth_trace.log_likelihood.front());
  for (size_t i = 1; i < from_truth_trace.log_likelihood.size(); ++i) {
    EXPECT_GE(from_truth_trace.log_likelihood[i], from_truth_trace.log_likelihood[i - 1] - 1e-9 * frames);
  }
}

TEST(Fhmm, SameSeedSameStart) {
  std::mt19937_64 rng(2);
  const Fhmm truth = RandomFhmm(2, 3, 3, rng);
  const std::vector<Eigen::MatrixXd> data = {Sample(truth, 50, rng)};
  const Fhmm a = InitialFhmm(data, 2, 3, 0.9, 7), b = InitialFhmm(data, 2, 3, 0.9, 7), c = InitialFhmm(data, 2, 3, 0.9, 8);
  EXPECT_EQ(a.weights[1], b.weights[1]);
  EXPECT_NE(a.weights[1], c.weights[1]);
  EXPECT_THROW(InitialFhmm({}, 2, 3, 0.9, 1), std::invalid_argument);
}

}  // namespace
}  // namespace irbench
