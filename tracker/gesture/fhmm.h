#pragma once
// The factorial hidden Markov model (thesis 5.2.2; Ghahramani and Jordan 1997,
// "Factorial hidden Markov models"): M chains of K states each, transiting
// independently, and one Gaussian observation of dimension D whose mean is
// the sum of one column per chain, mu_t = sum_m W_m S_m_t, with one full
// covariance. The thesis's model: M = 2 chains (the primary and the secondary
// arm), K = 5 states (the atoms), the matching-pursuit weight vector as the
// observation (D = K). Inference is exact over the K^M product states.

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "tracker/gesture/hmm.h"

namespace irbench {

struct Fhmm {
  std::vector<LogMarkovChain> chains;   // M chains, K states each
  std::vector<Eigen::MatrixXd> weights;  // M matrices, D x K
  Eigen::MatrixXd covariance;           // D x D

  int chain_count() const { return static_cast<int>(chains.size()); }
  int states_per_chain() const { return chains.empty() ? 0 : chains[0].size(); }
  int dimension() const { return static_cast<int>(covariance.rows()); }
  // K^M.
  int product_size() const;
  // Product state s = sum_m k_m K^m: chain m is in state k_m.
  std::vector<int> StatesOf(int product_state) const;
  // Throws std::invalid_argument unless the chains, weights and covariance agree.
  void Check() const;

  // D x K^M: the observation mean of every product state.
  Eigen::MatrixXd ProductMeans() const;
  // T x K^M emission log-densities of y (D x T).
  Eigen::MatrixXd EmissionLogLikelihoods(const Eigen::MatrixXd& y) const;
  // The equivalent flat chain over the K^M product states: initial and
  // transition probabilities the products of the chains'.
  LogMarkovChain ProductChain() const;

  // log p(y) by the forward recursion over the product states, the
  // transition applied one chain at a time: O(T M K^(M+1)) instead of the
  // flat chain's O(T K^(2M)).
  double LogLikelihood(const Eigen::MatrixXd& y) const;
  // The factored forward's log alpha, T x K^M (for tests and online use).
  Eigen::MatrixXd LogAlpha(const Eigen::MatrixXd& y) const;
};

// A starting point for Baum-Welch from the training data, seeded: sticky
// chains (self-transition `stay`), each chain's weight columns drawn from
// the data's frames divided by M plus a little noise, the data's covariance.
Fhmm InitialFhmm(const std::vector<Eigen::MatrixXd>& sequences, int chain_count, int states_per_chain, double stay,
                 uint64_t seed);

// Exact EM: the E-step over the product states, the M-step of Ghahramani and
// Jordan (W from the expected indicator products by a pseudo-inverse, the
// covariance from the residual), the chains from their marginal counts.
// Throws std::invalid_argument on empty data or a dimension mismatch.
TrainingTrace TrainFhmm(const std::vector<Eigen::MatrixXd>& sequences, const BaumWelchOptions& options,
                        const CovarianceOptions& covariance, Fhmm* model);

}  // namespace irbench
