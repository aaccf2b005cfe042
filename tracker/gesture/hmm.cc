#include "tracker/gesture/hmm.h"

#include <Eigen/Cholesky>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>

namespace irbench {
namespace {


double SafeLog(double p) { return p > 0 ? std::log(p) : kLogZero; }

void CheckEmission(const LogMarkovChain& chain, const Eigen::MatrixXd& log_emission) {
  if (log_emission.cols() != chain.size()) {
    throw std::invalid_argument("emission log-likelihoods have " + std::to_string(log_emission.cols()) +
                                " states, the chain " + std::to_string(chain.size()));
  }
}

// Sum of log-likelihoods of `sequences` after filling `posteriors`.
template <typename Emit>
double EStep(const LogMarkovChain& chain, size_t count, Emit emit, std::vector<Posteriors>* posteriors) {
  posteriors->clear();
  double total = 0;
  for (size_t s = 0; s < count; ++s) {
    posteriors->push_back(ForwardBackward(chain, emit(s)));
    total += posteriors->back().log_likelihood;
  }
  return total;
}

}  // namespace

double LogSumExp(const Eigen::Ref<const Eigen::VectorXd>& v) {
  if (v.size() == 0) return kLogZero;
  const double m = v.maxCoeff();
  if (m == kLogZero) return kLogZero;
  if (m == std::numeric_limits<double>::infinity()) return m;
  return m + std::log((v.array() - m).exp().sum());
}

void LogMarkovChain::Check() const {
  const int n = size();
  if (n == 0 || log_transition.rows() != n || log_transition.cols() != n) {
    throw std::invalid_argument("a Markov chain needs N initial probabilities and N x N transitions");
  }
  auto sums_to_one = [](const Eigen::VectorXd& log_p) { return std::abs(std::exp(LogSumExp(log_p)) - 1) < 1e-6; };
  if (!sums_to_one(log_initial)) throw std::invalid_argument("the initial probabilities do not sum to 1");
  for (int i = 0; i < n; ++i) {
    if (!sums_to_one(log_transition.row(i).transpose())) {
      throw std::invalid_argument("transition row " + std::to_string(i) + " does not sum to 1");
    }
  }
}

LogMarkovChain LogMarkovChain::FromProbabilities(const Eigen::VectorXd& initial, const Eigen::MatrixXd& transition) {
  LogMarkovChain c;
  c.log_initial = initial.unaryExpr([](double p) { return SafeLog(p); });
  c.log_transition = transition.unaryExpr([](double p) { return SafeLog(p); });
  return c;
}

LogMarkovChain StickyChain(int n, double stay) {
  if (n < 1 || !(stay > 0 && stay <= 1)) throw std::invalid_argument("StickyChain: n >= 1, 0 < stay <= 1");
  Eigen::MatrixXd a = Eigen::MatrixXd::Constant(n, n, n > 1 ? (1 - stay) / (n - 1) : 0.0);
  a.diagonal().setConstant(n > 1 ? stay : 1.0);
  return LogMarkovChain::FromProbabilities(Eigen::VectorXd::Constant(n, 1.0 / n), a);
}

double LogForward(const LogMarkovChain& chain, const Eigen::MatrixXd& log_emission, Eigen::MatrixXd* log_alpha) {
  CheckEmission(chain, log_emission);
  const int t_count = static_cast<int>(log_emission.rows()), n = chain.size();
  if (log_alpha) log_alpha->resize(t_count, n);
  if (t_count == 0) return 0;
  Eigen::VectorXd alpha = chain.log_initial + log_emission.row(0).transpose();
  if (log_alpha) log_alpha->row(0) = alpha.transpose();
  Eigen::VectorXd next(n), terms(n);
  for (int t = 1; t < t_count; ++t) {
    for (int j = 0; j < n; ++j) {
      terms = alpha + chain.log_transition.col(j);
      next(j) = LogSumExp(terms) + log_emission(t, j);
    }
    alpha.swap(next);
    if (log_alpha) log_alpha->row(t) = alpha.transpose();
  }
  return LogSumExp(alpha);
}

Posteriors ForwardBackward(const LogMarkovChain& chain, const Eigen::MatrixXd& log_emission) {
  CheckEmission(chain, log_emission);
  const int t_count = static_cast<int>(log_emission.rows()), n = chain.size();
  if (t_count < 1) throw std::invalid_argument("ForwardBackward needs at least one frame");
  Posteriors p;
  p.log_likelihood = LogForward(chain, log_emission, &p.log_alpha);
  if (!std::isfinite(p.log_likelihood)) throw std::domain_error("the sequence has zero likelihood under the model");
  p.log_beta.resize(t_count, n);
  p.log_beta.row(t_count - 1).setZero();
  Eigen::VectorXd terms(n);
  for (int t = t_count - 2; t >= 0; --t) {
    const Eigen::VectorXd after = log_emission.row(t + 1).transpose() + p.log_beta.row(t + 1).transpose();
    for (int i = 0; i < n; ++i) {
      terms = chain.log_transition.row(i).transpose() + after;
      p.log_beta(t, i) = LogSumExp(terms);
    }
  }
  p.gamma = (p.log_alpha + p.log_beta).array() - p.log_likelihood;
  p.gamma = p.gamma.array().exp();
  p.xi_sum = Eigen::MatrixXd::Zero(n, n);
  for (int t = 0; t + 1 < t_count; ++t) {
    for (int i = 0; i < n; ++i) {
      if (p.log_alpha(t, i) == kLogZero) continue;
      for (int j = 0; j < n; ++j) {
        const double l = p.log_alpha(t, i) + chain.log_transition(i, j) + log_emission(t + 1, j) +
                         p.log_beta(t + 1, j) - p.log_likelihood;
        if (l != kLogZero) p.xi_sum(i, j) += std::exp(l);
      }
    }
  }
  return p;
}

std::vector<int> Viterbi(const LogMarkovChain& chain, const Eigen::MatrixXd& log_emission, double* log_probability) {
  CheckEmission(chain, log_emission);
  const int t_count = static_cast<int>(log_emission.rows()), n = chain.size();
  if (t_count < 1) throw std::invalid_argument("Viterbi needs at least one frame");
  Eigen::VectorXd delta = chain.log_initial + log_emission.row(0).transpose();
  Eigen::MatrixXi back(t_count, n);
  Eigen::VectorXd next(n);
  for (int t = 1; t < t_count; ++t) {
    for (int j = 0; j < n; ++j) {
      int best = 0;
      double best_value = delta(0) + chain.log_transition(0, j);
      for (int i = 1; i < n; ++i) {
        const double v = delta(i) + chain.log_transition(i, j);
        if (v > best_value) best_value = v, best = i;
      }
      next(j) = best_value + log_emission(t, j);
      back(t, j) = best;
    }
    delta.swap(next);
  }
  std::vector<int> path(t_count);
  int last = 0;
  for (int j = 1; j < n; ++j) {
    if (delta(j) > delta(last)) last = j;
  }
  if (log_probability) *log_probability = delta(last);
  path[t_count - 1] = last;
  for (int t = t_count - 1; t > 0; --t) path[t - 1] = back(t, path[t]);
  return path;
}

void BaumWelchOptions::Check() const {
  if (max_iterations < 0) throw std::invalid_argument("max_iterations must be >= 0");
  if (!(tolerance_per_frame >= 0)) throw std::invalid_argument("tolerance_per_frame must be >= 0");
  if (!(pseudo_count >= 0) || !std::isfinite(pseudo_count)) throw std::invalid_argument("pseudo_count must be >= 0");
}

TrainingTrace RunBaumWelch(double log_likelihood, size_t frames, const BaumWelchOptions& options,
                           const std::function<double()>& iterate) {
  TrainingTrace trace;
  double ll = log_likelihood;
  for (int it = 0; it < options.max_iterations; ++it) {
    trace.log_likelihood.push_back(ll);
    const double next = iterate();
    ++trace.iterations;
    const bool done = next - ll < options.tolerance_per_frame * frames;
    ll = next;
    if (done) {
      trace.converged = true;
      break;
    }
  }
  trace.final_log_likelihood = ll;
  return trace;
}

void ChainCounts::Add(const Posteriors& p) {
  initial += p.gamma.row(0).transpose();
  transition += p.xi_sum;
}

LogMarkovChain ChainCounts::Estimate(const LogMarkovChain& previous, const BaumWelchOptions& options) const {
  const int n = static_cast<int>(initial.size());
  const double a = options.pseudo_count;
  LogMarkovChain c = previous;
  if (!options.fixed_initial) {
    const Eigen::VectorXd counts = initial.array() + a;
    if (counts.sum() > 0) c.log_initial = (counts / counts.sum()).unaryExpr([](double p) { return SafeLog(p); });
  }
  for (int i = 0; i < n; ++i) {
    const Eigen::VectorXd row = transition.row(i).transpose().array() + a;
    if (row.sum() > 0) {
      c.log_transition.row(i) = (row / row.sum()).unaryExpr([](double p) { return SafeLog(p); }).transpose();
    }
  }
  return c;
}

Eigen::MatrixXd DiscreteHmm::EmissionLogLikelihoods(const std::vector<int>& y) const {
  Eigen::MatrixXd out(y.size(), chain.size());
  for (size_t t = 0; t < y.size(); ++t) {
    if (y[t] < 0 || y[t] >= symbols()) {
      throw std::out_of_range("symbol " + std::to_string(y[t]) + " outside 0.." + std::to_string(symbols() - 1));
    }
    out.row(t) = log_emission.col(y[t]).transpose();
  }
  return out;
}

double DiscreteHmm::LogLikelihood(const std::vector<int>& y) const {
  return LogForward(chain, EmissionLogLikelihoods(y));
}

TrainingTrace TrainDiscreteHmm(const std::vector<std::vector<int>>& sequences, const BaumWelchOptions& options,
                               DiscreteHmm* hmm) {
  options.Check();
  hmm->chain.Check();
  size_t frames = 0;
  for (const auto& s : sequences) {
    if (s.empty()) throw std::invalid_argument("an empty training sequence");
    frames += s.size();
  }
  if (frames == 0) throw std::invalid_argument("no training sequences");
  const int n = hmm->chain.size(), m = hmm->symbols();
  std::vector<Posteriors> post;
  auto emit = [&](size_t s) { return hmm->EmissionLogLikelihoods(sequences[s]); };
  const double ll = EStep(hmm->chain, sequences.size(), emit, &post);
  return RunBaumWelch(ll, frames, options, [&] {
    ChainCounts counts(n);
    Eigen::MatrixXd emission = Eigen::MatrixXd::Constant(n, m, options.pseudo_count);
    for (size_t s = 0; s < sequences.size(); ++s) {
      counts.Add(post[s]);
      for (size_t t = 0; t < sequences[s].size(); ++t) emission.col(sequences[s][t]) += post[s].gamma.row(t).transpose();
    }
    hmm->chain = counts.Estimate(hmm->chain, options);
    for (int j = 0; j < n; ++j) {
      const double total = emission.row(j).sum();
      if (total > 0) {
        hmm->log_emission.row(j) = (emission.row(j) / total).unaryExpr([](double p) { return SafeLog(p); });
      }
    }
    return EStep(hmm->chain, sequences.size(), emit, &post);
  });
}

Eigen::MatrixXd GaussianLogDensities(const Eigen::MatrixXd& y, const Eigen::MatrixXd& means,
                                     const Eigen::MatrixXd& covariance) {
  const int d = static_cast<int>(covariance.rows());
  if (y.rows() != d || means.rows() != d || covariance.cols() != d) {
    throw std::invalid_argument("observation, mean and covariance dimensions differ");
  }
  const Eigen::LLT<Eigen::MatrixXd> llt(covariance);
  if (llt.info() != Eigen::Success) throw std::domain_error("the covariance is not positive definite");
  const Eigen::MatrixXd l = llt.matrixL();
  const double log_det = 2 * l.diagonal().array().log().sum();
  const double constant = -0.5 * (d * std::log(2 * std::numbers::pi) + log_det);
  Eigen::MatrixXd out(y.cols(), means.cols());
  for (int j = 0; j < means.cols(); ++j) {
    const Eigen::MatrixXd z = llt.matrixL().solve(y.colwise() - means.col(j));
    out.col(j) = (constant - 0.5 * z.colwise().squaredNorm().array()).transpose();
  }
  return out;
}

Eigen::MatrixXd GaussianHmm::EmissionLogLikelihoods(const Eigen::MatrixXd& y) const {
  return GaussianLogDensities(y, means, covariance);
}

double GaussianHmm::LogLikelihood(const Eigen::MatrixXd& y) const {
  return LogForward(chain, EmissionLogLikelihoods(y));
}

TrainingTrace TrainGaussianHmm(const std::vector<Eigen::MatrixXd>& sequences, const BaumWelchOptions& options,
                               const CovarianceOptions& covariance, GaussianHmm* hmm) {
  options.Check();
  hmm->chain.Check();
  if (!(covariance.ridge >= 0)) throw std::invalid_argument("the covariance ridge must be >= 0");
  const int n = hmm->chain.size(), d = static_cast<int>(hmm->means.rows());
  size_t frames = 0;
  for (const auto& s : sequences) {
    if (s.cols() == 0 || s.rows() != d) throw std::invalid_argument("a training sequence is empty or of another dimension");
    frames += s.cols();
  }
  if (frames == 0) throw std::invalid_argument("no training sequences");
  std::vector<Posteriors> post;
  auto emit = [&](size_t s) { return hmm->EmissionLogLikelihoods(sequences[s]); };
  const double ll = EStep(hmm->chain, sequences.size(), emit, &post);
  return RunBaumWelch(ll, frames, options, [&] {
    ChainCounts counts(n);
    Eigen::VectorXd weight = Eigen::VectorXd::Zero(n);
    Eigen::MatrixXd sum = Eigen::MatrixXd::Zero(d, n);
    for (size_t s = 0; s < sequences.size(); ++s) {
      counts.Add(post[s]);
      weight += post[s].gamma.colwise().sum().transpose();
      sum += sequences[s] * post[s].gamma;
    }
    hmm->chain = counts.Estimate(hmm->chain, options);
    for (int j = 0; j < n; ++j) {
      if (weight(j) > 0) hmm->means.col(j) = sum.col(j) / weight(j);
    }
    Eigen::MatrixXd scatter = Eigen::MatrixXd::Zero(d, d);
    for (size_t s = 0; s < sequences.size(); ++s) {
      for (int j = 0; j < n; ++j) {
        const Eigen::MatrixXd centred = sequences[s].colwise() - hmm->means.col(j);
        scatter += centred * post[s].gamma.col(j).asDiagonal() * centred.transpose();
      }
    }
    hmm->covariance = scatter / static_cast<double>(frames);
    hmm->covariance = 0.5 * (hmm->covariance + hmm->covariance.transpose()).eval();
    hmm->covariance.diagonal().array() += covariance.ridge;
    return EStep(hmm->chain, sequences.size(), emit, &post);
  });
}

}  // namespace irbench
