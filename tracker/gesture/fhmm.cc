#include "tracker/gesture/fhmm.h"

#include <Eigen/QR>
#include <random>
#include <stdexcept>
#include <string>

namespace irbench {

int Fhmm::product_size() const {
  int n = 1;
  for (int m = 0; m < chain_count(); ++m) n *= states_per_chain();
  return n;
}

std::vector<int> Fhmm::StatesOf(int product_state) const {
  std::vector<int> k(chain_count());
  for (int m = 0; m < chain_count(); ++m) {
    k[m] = product_state % states_per_chain();
    product_state /= states_per_chain();
  }
  return k;
}

void Fhmm::Check() const {
  if (chains.empty() || weights.size() != chains.size()) {
    throw std::invalid_argument("an FHMM needs at least one chain and one weight matrix per chain");
  }
  const int k = states_per_chain(), d = dimension();
  if (covariance.cols() != d || d == 0) throw std::invalid_argument("the FHMM's covariance is not square");
  for (size_t m = 0; m < chains.size(); ++m) {
    chains[m].Check();
    if (chains[m].size() != k) throw std::invalid_argument("the FHMM's chains differ in size");
    if (weights[m].rows() != d || weights[m].cols() != k) {
      throw std::invalid_argument("weight matrix " + std::to_string(m) + " is not D x K");
    }
  }
}

Eigen::MatrixXd Fhmm::ProductMeans() const {
  const int n = product_size();
  Eigen::MatrixXd means = Eigen::MatrixXd::Zero(dimension(), n);
  for (int s = 0; s < n; ++s) {
    const std::vector<int> k = StatesOf(s);
    for (int m = 0; m < chain_count(); ++m) means.col(s) += weights[m].col(k[m]);
  }
  return means;
}

Eigen::MatrixXd Fhmm::EmissionLogLikelihoods(const Eigen::MatrixXd& y) const {
  return GaussianLogDensities(y, ProductMeans(), covariance);
}

LogMarkovChain Fhmm::ProductChain() const {
  const int n = product_size();
  LogMarkovChain flat;
  flat.log_initial = Eigen::VectorXd::Zero(n);
  flat.log_transition = Eigen::MatrixXd::Zero(n, n);
  for (int s = 0; s < n; ++s) {
    const std::vector<int> from = StatesOf(s);
    for (int m = 0; m < chain_count(); ++m) flat.log_initial(s) += chains[m].log_initial(from[m]);
    for (int r = 0; r < n; ++r) {
      const std::vector<int> to = StatesOf(r);
      for (int m = 0; m < chain_count(); ++m) flat.log_transition(s, r) += chains[m].log_transition(from[m], to[m]);
    }
  }
  return flat;
}

Eigen::MatrixXd Fhmm::LogAlpha(const Eigen::MatrixXd& y) const {
  Check();
  const Eigen::MatrixXd emission = EmissionLogLikelihoods(y);
  const int t_count = static_cast<int>(emission.rows()), n = product_size(), k = states_per_chain();
  Eigen::MatrixXd log_alpha(t_count, n);
  if (t_count == 0) return log_alpha;
  Eigen::VectorXd alpha(n), next(n), terms(k);
  for (int s = 0; s < n; ++s) {
    const std::vector<int> states = StatesOf(s);
    alpha(s) = emission(0, s);
    for (int m = 0; m < chain_count(); ++m) alpha(s) += chains[m].log_initial(states[m]);
  }
  log_alpha.row(0) = alpha.transpose();
  for (int t = 1; t < t_count; ++t) {
    // One chain at a time: sum chain m's previous state out while the other
    // chains' states stay (they are summed by their own passes).
    int stride = 1;
    for (int m = 0; m < chain_count(); ++m) {
      for (int s = 0; s < n; ++s) {
        const int j = (s / stride) % k;
        const int base = s - j * stride;
        for (int i = 0; i < k; ++i) terms(i) = alpha(base + i * stride) + chains[m].log_transition(i, j);
        next(s) = LogSumExp(terms);
      }
      alpha.swap(next);
      stride *= k;
    }
    alpha += emission.row(t).transpose();
    log_alpha.row(t) = alpha.transpose();
  }
  return log_alpha;
}

double Fhmm::LogLikelihood(const Eigen::MatrixXd& y) const {
  if (y.cols() == 0) return 0;
  const Eigen::MatrixXd log_alpha = LogAlpha(y);
  return LogSumExp(log_alpha.row(log_alpha.rows() - 1).transpose());
}

Fhmm InitialFhmm(const std::vector<Eigen::MatrixXd>& sequences, int chain_count, int states_per_chain, double stay,
                 uint64_t seed) {
  if (chain_count < 1 || states_per_chain < 1) throw std::invalid_argument("an FHMM needs M >= 1 and K >= 1");
  std::vector<const Eigen::MatrixXd*> nonempty;
  long frames = 0;
  for (const auto& s : sequences) {
    if (s.cols() > 0) nonempty.push_back(&s), frames += s.cols();
  }
  if (nonempty.empty()) throw std::invalid_argument("no training frames");
  const int d = static_cast<int>(nonempty[0]->rows());
  Eigen::VectorXd mean = Eigen::VectorXd::Zero(d);
  Eigen::MatrixXd second = Eigen::MatrixXd::Zero(d, d);
  for (const auto* s : nonempty) {
    if (s->rows() != d) throw std::invalid_argument("training sequences differ in dimension");
    mean += s->rowwise().sum();
    second += *s * s->transpose();
  }
  mean /= static_cast<double>(frames);
  Fhmm model;
  model.covariance = second / static_cast<double>(frames) - mean * mean.transpose();
  const double scale = std::max(model.covariance.trace() / d, 1e-12);
  model.covariance.diagonal().array() += 1e-3 * scale;
  std::mt19937_64 rng(seed);
  for (int m = 0; m < chain_count; ++m) {
    model.chains.push_back(StickyChain(states_per_chain, stay));
    Eigen::MatrixXd w(d, states_per_chain);
    for (int k = 0; k < states_per_chain; ++k) {
      const auto* s = nonempty[static_cast<size_t>(UniformDraw(rng) * nonempty.size())];
      const int t = static_cast<int>(UniformDraw(rng) * s->cols());
      w.col(k) = s->col(t) / chain_count;
      for (int i = 0; i < d; ++i) w(i, k) += 0.1 * std::sqrt(scale) * (UniformDraw(rng) - 0.5);
    }
    model.weights.push_back(w);
  }
  return model;
}

TrainingTrace TrainFhmm(const std::vector<Eigen::MatrixXd>& sequences, const BaumWelchOptions& options,
                        const CovarianceOptions& covariance, Fhmm* model) {
  options.Check();
  model->Check();
  if (!(covariance.ridge >= 0)) throw std::invalid_argument("the covariance ridge must be >= 0");
  const int d = model->dimension(), k = model->states_per_chain(), chains = model->chain_count();
  const int n = model->product_size(), mk = chains * k;
  size_t frames = 0;
  for (const auto& s : sequences) {
    if (s.cols() == 0 || s.rows() != d) throw std::invalid_argument("a training sequence is empty or of another dimension");
    frames += s.cols();
  }
  if (frames == 0) throw std::invalid_argument("no training sequences");
  // The indicator vector (length M K) of every product state.
  Eigen::MatrixXd indicator = Eigen::MatrixXd::Zero(mk, n);
  for (int s = 0; s < n; ++s) {
    const std::vector<int> states = model->StatesOf(s);
    for (int m = 0; m < chains; ++m) indicator(m * k + states[m], s) = 1;
  }
  Eigen::MatrixXd yy = Eigen::MatrixXd::Zero(d, d);
  for (const auto& s : sequences) yy += s * s.transpose();

  std::vector<Posteriors> post;
  auto e_step = [&]() {
    post.clear();
    const LogMarkovChain flat = model->ProductChain();
    double total = 0;
    for (const auto& s : sequences) {
      post.push_back(ForwardBackward(flat, model->EmissionLogLikelihoods(s)));
      total += post.back().log_likelihood;
    }
    return total;
  };
  const double ll = e_step();
  return RunBaumWelch(ll, frames, options, [&] {
    Eigen::MatrixXd ys = Eigen::MatrixXd::Zero(d, mk);   // sum y_t E[S_t]'
    Eigen::MatrixXd ss = Eigen::MatrixXd::Zero(mk, mk);  // sum E[S_t S_t']
    std::vector<ChainCounts> counts(chains, ChainCounts(k));
    for (size_t q = 0; q < sequences.size(); ++q) {
      const Posteriors& p = post[q];
      const Eigen::MatrixXd expected = indicator * p.gamma.transpose();  // MK x T
      ys += sequences[q] * expected.transpose();
      const Eigen::VectorXd occupancy = p.gamma.colwise().sum().transpose();
      ss += indicator * occupancy.asDiagonal() * indicator.transpose();
      for (int m = 0; m < chains; ++m) {
        // Chain m's marginal posteriors: its initial state and its transitions.
        Posteriors marginal;
        marginal.gamma = Eigen::MatrixXd::Zero(1, k);
        marginal.xi_sum = Eigen::MatrixXd::Zero(k, k);
        for (int s = 0; s < n; ++s) {
          const int from = model->StatesOf(s)[m];
          marginal.gamma(0, from) += p.gamma(0, s);
          for (int r = 0; r < n; ++r) marginal.xi_sum(from, model->StatesOf(r)[m]) += p.xi_sum(s, r);
        }
        counts[m].Add(marginal);
      }
    }
    for (int m = 0; m < chains; ++m) model->chains[m] = counts[m].Estimate(model->chains[m], options);
    Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> cod(ss);
    cod.setThreshold(1e-10);
    const Eigen::MatrixXd w = ys * cod.pseudoInverse();
    for (int m = 0; m < chains; ++m) model->weights[m] = w.middleCols(m * k, k);
    Eigen::MatrixXd sigma = (yy - w * ys.transpose()) / static_cast<double>(frames);
    sigma = 0.5 * (sigma + sigma.transpose()).eval();
    sigma.diagonal().array() += covariance.ridge;
    model->covariance = sigma;
    return e_step();
  });
}

}  // namespace irbench
