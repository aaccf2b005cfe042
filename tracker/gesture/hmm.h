#pragma once
// Hidden Markov models in log space (thesis 5.2; Rabiner 1989, "A tutorial on
// hidden Markov models"): the forward and backward recursions, state
// posteriors, Viterbi and Baum-Welch. The recursions take the emission
// log-likelihoods per frame and state, so the discrete and the Gaussian
// observation models (and the factorial model's product states, fhmm.h) share
// them. Every probability is a logarithm and every sum a log-sum-exp, so long
// sequences neither underflow nor give NaN; a probability of 0 is -inf and
// is handled as such (a state that cannot be reached stays at -inf).

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <limits>
#include <random>
#include <vector>

namespace irbench {

// log(0): a probability of 0 in log space.
inline constexpr double kLogZero = -std::numeric_limits<double>::infinity();

// Uniform in [0, 1) from the generator's raw bits (the standard's
// distributions differ between libraries; this does not): the models'
// seeded random starts.
inline double UniformDraw(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }

// log(sum(exp(v))), -inf for an empty vector or one that is all -inf.
double LogSumExp(const Eigen::Ref<const Eigen::VectorXd>& v);

// A first-order Markov chain over N states.
struct LogMarkovChain {
  Eigen::VectorXd log_initial;     // N: log P(q_1 = i)
  Eigen::MatrixXd log_transition;  // N x N: (i, j) = log P(q_{t+1} = j | q_t = i)

  int size() const { return static_cast<int>(log_initial.size()); }
  // Throws std::invalid_argument unless the sizes agree and the initial
  // distribution and every row of the transitions sum to 1 within 1e-6.
  void Check() const;
  // From probabilities (logarithms taken; zeros become -inf).
  static LogMarkovChain FromProbabilities(const Eigen::VectorXd& initial, const Eigen::MatrixXd& transition);
};

// The forward-backward pass over one sequence of T frames.
struct Posteriors {
  double log_likelihood = 0;   // log p(y_1..T)
  Eigen::MatrixXd log_alpha;   // T x N: log p(y_1..t, q_t = j)
  Eigen::MatrixXd log_beta;    // T x N: log p(y_t+1..T | q_t = j)
  Eigen::MatrixXd gamma;       // T x N: P(q_t = j | y)
  Eigen::MatrixXd xi_sum;      // N x N: sum over t of P(q_t = i, q_t+1 = j | y)
};

// log p(y_1..T) by the forward recursion; `log_emission` is T x N,
// (t, j) = log p(y_t | q_t = j). -inf when the sequence is impossible; 0 for
// T = 0. Fills `log_alpha` when given.
double LogForward(const LogMarkovChain& chain, const Eigen::MatrixXd& log_emission,
                  Eigen::MatrixXd* log_alpha = nullptr);

// The forward and backward recursions and the posteriors. T >= 1; the
// sequence must be possible (finite likelihood), else std::domain_error.
Posteriors ForwardBackward(const LogMarkovChain& chain, const Eigen::MatrixXd& log_emission);

// The most probable state path (ties go to the lower state index); its joint
// log-probability log p(q, y) in `log_probability` when given. T >= 1.
std::vector<int> Viterbi(const LogMarkovChain& chain, const Eigen::MatrixXd& log_emission,
                         double* log_probability = nullptr);

// Baum-Welch (EM) settings shared by the models.
struct BaumWelchOptions {
  int max_iterations = 100;
  // Stop when the log-likelihood per frame gains less than this.
  double tolerance_per_frame = 1e-7;
  // Dirichlet pseudo-counts added to every initial, transition and (discrete)
  // emission count: 0 is maximum likelihood; > 0 is the maximum a posteriori
  // estimate, which keeps symbols or transitions unseen in training possible.
  double pseudo_count = 0;
  // Keep the initial distribution as given (the thesis: a gesture starts at rest).
  bool fixed_initial = false;

  void Check() const;  // throws std::invalid_argument
};

// What a training run did: the total log-likelihood of the training data
// before each update (EM never lowers it at pseudo_count 0), and the final one.
struct TrainingTrace {
  std::vector<double> log_likelihood;
  double final_log_likelihood = 0;
  int iterations = 0;
  bool converged = false;
};

// The EM loop the models share: `iterate` re-estimates the model from the
// current posteriors, runs the next E-step and returns its log-likelihood.
// Starts from `log_likelihood` (the first E-step's); stops after
// max_iterations or when the gain per frame (of `frames`) falls below
// tolerance_per_frame.
TrainingTrace RunBaumWelch(double log_likelihood, size_t frames, const BaumWelchOptions& options,
                           const std::function<double()>& iterate);

// The expected counts of one chain over a set of sequences, summed.
struct ChainCounts {
  Eigen::VectorXd initial;
  Eigen::MatrixXd transition;
  explicit ChainCounts(int n) : initial(Eigen::VectorXd::Zero(n)), transition(Eigen::MatrixXd::Zero(n, n)) {}
  void Add(const Posteriors& p);
  // The re-estimated chain (M-step) with `options.pseudo_count` added;
  // `previous`'s initial distribution is kept when options.fixed_initial. A
  // row with no counts and no pseudo-count keeps `previous`'s row.
  LogMarkovChain Estimate(const LogMarkovChain& previous, const BaumWelchOptions& options) const;
};

// An HMM with discrete observations: symbols 0..M-1 (thesis 5.2.1's atoms).
struct DiscreteHmm {
  LogMarkovChain chain;
  Eigen::MatrixXd log_emission;  // N x M: (j, k) = log P(y = k | q = j)

  int symbols() const { return static_cast<int>(log_emission.cols()); }
  // T x N. Throws std::out_of_range for a symbol outside 0..M-1.
  Eigen::MatrixXd EmissionLogLikelihoods(const std::vector<int>& y) const;
  double LogLikelihood(const std::vector<int>& y) const;
};

// Baum-Welch from `hmm` as the starting point, over all `sequences` (each
// non-empty). Throws std::invalid_argument on empty data.
TrainingTrace TrainDiscreteHmm(const std::vector<std::vector<int>>& sequences, const BaumWelchOptions& options,
                               DiscreteHmm* hmm);

// An HMM with Gaussian observations: one mean per state and one full
// covariance shared by all states (tied: the thesis's weight vectors are few
// per state, too few for a covariance each).
struct GaussianHmm {
  LogMarkovChain chain;
  Eigen::MatrixXd means;       // D x N
  Eigen::MatrixXd covariance;  // D x D, symmetric positive definite

  // y: D x T; returns T x N. Throws std::domain_error when the covariance is
  // not positive definite.
  Eigen::MatrixXd EmissionLogLikelihoods(const Eigen::MatrixXd& y) const;
  double LogLikelihood(const Eigen::MatrixXd& y) const;
};

// The Gaussian log-density of every column of `y` (D x T) about each column of
// `means` (D x N) with covariance `covariance`: T x N. Throws std::domain_error
// when the covariance is not positive definite.
Eigen::MatrixXd GaussianLogDensities(const Eigen::MatrixXd& y, const Eigen::MatrixXd& means,
                                     const Eigen::MatrixXd& covariance);

// Settings of the Gaussian models' covariance update.
struct CovarianceOptions {
  // Added to the covariance's diagonal after each update (a floor that keeps
  // it invertible when the data span fewer than D dimensions; 0 is maximum
  // likelihood).
  double ridge = 0;
};

TrainingTrace TrainGaussianHmm(const std::vector<Eigen::MatrixXd>& sequences, const BaumWelchOptions& options,
                               const CovarianceOptions& covariance, GaussianHmm* hmm);

// A chain of `n` states with self-transition `stay` and the rest spread evenly,
// started uniformly: the usual starting point of Baum-Welch.
LogMarkovChain StickyChain(int n, double stay);

}  // namespace irbench
