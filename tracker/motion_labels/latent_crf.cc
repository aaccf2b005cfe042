#include "tracker/motion_labels/latent_crf.h"

#include <lbfgs.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>

#include "tracker/gesture/hmm.h"

namespace irbench {
namespace {

constexpr double kNegInf = -std::numeric_limits<double>::infinity();

// The chain's potentials as a log Markov chain with no start potential
// (ForwardBackward needs no normalisation: it returns log Z as the
// "likelihood" and the marginals normalised by it).
LogMarkovChain ChainOf(const LatentCrf& model) {
  return LogMarkovChain{Eigen::VectorXd::Zero(model.states()), model.transition()};
}

void CheckSequence(const LatentCrf& model, const CrfSequence& s, size_t index) {
  const std::string where = "sequence " + std::to_string(index);
  if (s.features.rows() < 1) throw std::invalid_argument(where + " has no frames");
  if (s.features.cols() != model.dims()) throw std::invalid_argument(where + ": features do not fit the model");
  if (s.labels.size() != static_cast<size_t>(s.features.rows())) {
    throw std::invalid_argument(where + ": one label per frame needed");
  }
  for (int l : s.labels) {
    if (l < 0 || l >= model.labels()) throw std::invalid_argument(where + ": a label out of range");
  }
  if (!s.features.allFinite()) throw std::invalid_argument(where + ": features must be finite");
}

// The objective over sequences whose window features are built once.
class Objective {
 public:
  Objective(const LatentCrf& shape, const std::vector<CrfSequence>& sequences) : sequences_(sequences) {
    for (size_t i = 0; i < sequences.size(); ++i) {
      CheckSequence(shape, sequences[i], i);
      windows_.push_back(shape.WindowFeatures(sequences[i].features));
    }
  }

  double Evaluate(const LatentCrf& model, double sigma, Eigen::VectorXd* gradient, CrfNumerator numerator) const {
    const bool path = numerator == CrfNumerator::kPath ||
                      (numerator == CrfNumerator::kAuto && model.states_per_label() == 1);
    if (path && model.states_per_label() != 1) {
      throw std::invalid_argument("the labelled path's score needs one state per label");
    }
    const int n = model.states();
    Eigen::MatrixXd g_state = Eigen::MatrixXd::Zero(n, model.window_dims());
    Eigen::MatrixXd g_transition = Eigen::MatrixXd::Zero(n, n);
    const LogMarkovChain chain = ChainOf(model);
    double value = 0;
    for (size_t s = 0; s < sequences_.size(); ++s) {
      const Eigen::MatrixXd& w = windows_[s];
      const std::vector<int>& y = sequences_[s].labels;
      const int t_count = static_cast<int>(w.rows());
      const Eigen::MatrixXd potentials = w * model.state_weights().transpose();
      const Posteriors all = ForwardBackward(chain, potentials);
      Eigen::MatrixXd gamma_y = Eigen::MatrixXd::Zero(t_count, n);
      Eigen::MatrixXd xi_y = Eigen::MatrixXd::Zero(n, n);
      double log_z_y = 0;
      if (path) {
        for (int t = 0; t < t_count; ++t) {
          log_z_y += potentials(t, y[t]);
          gamma_y(t, y[t]) = 1;
          if (t > 0) {
            log_z_y += model.transition()(y[t - 1], y[t]);
            xi_y(y[t - 1], y[t]) += 1;
          }
        }
      } else {
        Eigen::MatrixXd restricted = Eigen::MatrixXd::Constant(t_count, n, kNegInf);
        const int k = model.states_per_label();
        for (int t = 0; t < t_count; ++t) restricted.row(t).segment(y[t] * k, k) = potentials.row(t).segment(y[t] * k, k);
        const Posteriors labelled = ForwardBackward(chain, restricted);
        log_z_y = labelled.log_likelihood;
        gamma_y = labelled.gamma;
        xi_y = labelled.xi_sum;
      }
      value += all.log_likelihood - log_z_y;
      if (gradient) {
        g_state.noalias() += (all.gamma - gamma_y).transpose() * w;
        g_transition += all.xi_sum - xi_y;
      }
    }
    const Eigen::VectorXd theta = model.Parameters();
    if (sigma > 0) value += theta.squaredNorm() / (2 * sigma * sigma);
    if (gradient) {
      gradient->resize(theta.size());
      const Eigen::Index state_count = g_state.size();
      Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(gradient->data(), n,
                                                                                          model.window_dims()) = g_state;
      Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(
          gradient->data() + state_count, n, n) = g_transition;
      if (sigma > 0) *gradient += theta / (sigma * sigma);
    }
    return value;
  }

 private:
  const std::vector<CrfSequence>& sequences_;
  std::vector<Eigen::MatrixXd> windows_;
};

struct TrainingState {
  LatentCrf* model;
  const Objective* objective;
  const CrfTrainingOptions* options;
};

lbfgsfloatval_t EvaluateForLbfgs(void* instance, const lbfgsfloatval_t* x, lbfgsfloatval_t* g, const int n,
                                 const lbfgsfloatval_t /*step*/) {
  auto* state = static_cast<TrainingState*>(instance);
  state->model->SetParameters(Eigen::Map<const Eigen::VectorXd>(x, n));
  Eigen::VectorXd gradient;
  const double value = state->objective->Evaluate(*state->model, state->options->sigma, &gradient, CrfNumerator::kAuto);
  Eigen::Map<Eigen::VectorXd>(g, n) = gradient;
  return value;
}

int ProgressForLbfgs(void* instance, const lbfgsfloatval_t*, const lbfgsfloatval_t*, const lbfgsfloatval_t fx,
                     const lbfgsfloatval_t, const lbfgsfloatval_t, const lbfgsfloatval_t, int, int k, int) {
  auto* state = static_cast<TrainingState*>(instance);
  if (state->options->progress) state->options->progress(k, fx);
  return 0;
}

std::string LbfgsStatusText(int status) {
  switch (status) {
    case LBFGS_SUCCESS: return "converged";
    case LBFGS_STOP: return "stopped";
    case LBFGS_ALREADY_MINIMIZED: return "already at a minimum";
    case LBFGSERR_MAXIMUMITERATION: return "reached the iteration limit";
    case LBFGSERR_ROUNDING_ERROR: return "stopped by rounding errors (at a minimum to machine precision)";
    case LBFGSERR_MAXIMUMLINESEARCH: return "the line search reached its limit";
    case LBFGSERR_MINIMUMSTEP: return "the line search step became too small";
    case LBFGSERR_MAXIMUMSTEP: return "the line search step became too large";
    case LBFGSERR_CANCELED: return "cancelled";
    default: return "liblbfgs status " + std::to_string(status);
  }
}

}  // namespace

LatentCrf::LatentCrf(int labels, int states_per_label, int dims, int window)
    : labels_(labels), states_per_label_(states_per_label), dims_(dims), window_(window) {
  if (labels < 1 || states_per_label < 1 || dims < 1 || window < 0) {
    throw std::invalid_argument("LatentCrf: labels, states per label and dims >= 1, window >= 0");
  }
  state_weights_ = Eigen::MatrixXd::Zero(states(), window_dims());
  transition_ = Eigen::MatrixXd::Zero(states(), states());
}

int LatentCrf::ParameterCount() const { return states() * window_dims() + states() * states(); }

Eigen::VectorXd LatentCrf::Parameters() const {
  Eigen::VectorXd theta(ParameterCount());
  using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  Eigen::Map<RowMajor>(theta.data(), states(), window_dims()) = state_weights_;
  Eigen::Map<RowMajor>(theta.data() + state_weights_.size(), states(), states()) = transition_;
  return theta;
}

void LatentCrf::SetParameters(const Eigen::VectorXd& theta) {
  if (theta.size() != ParameterCount()) throw std::invalid_argument("LatentCrf: wrong parameter count");
  using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  state_weights_ = Eigen::Map<const RowMajor>(theta.data(), states(), window_dims());
  transition_ = Eigen::Map<const RowMajor>(theta.data() + state_weights_.size(), states(), states());
}

Eigen::MatrixXd LatentCrf::WindowFeatures(const Eigen::MatrixXd& features) const {
  const int t_count = static_cast<int>(features.rows());
  Eigen::MatrixXd w(t_count, window_dims());
  for (int t = 0; t < t_count; ++t) {
    for (int o = -window_; o <= window_; ++o) {
      const int source = std::clamp(t + o, 0, t_count - 1);
      w.row(t).segment((o + window_) * dims_, dims_) = features.row(source);
    }
    w(t, window_dims() - 1) = 1.0;
  }
  return w;
}

Eigen::MatrixXd LatentCrf::StatePotentials(const Eigen::MatrixXd& features) const {
  if (features.cols() != dims_) throw std::invalid_argument("LatentCrf: features do not fit the model");
  return WindowFeatures(features) * state_weights_.transpose();
}

Eigen::MatrixXd LatentCrf::LabelMarginals(const Eigen::MatrixXd& features) const {
  const Posteriors p = ForwardBackward(ChainOf(*this), StatePotentials(features));
  Eigen::MatrixXd marginals = Eigen::MatrixXd::Zero(p.gamma.rows(), labels_);
  for (int h = 0; h < states(); ++h) marginals.col(LabelOf(h)) += p.gamma.col(h);
  return marginals;
}

std::vector<int> LatentCrf::Decode(const Eigen::MatrixXd& features) const {
  const Eigen::MatrixXd m = LabelMarginals(features);
  std::vector<int> out(m.rows());
  for (Eigen::Index t = 0; t < m.rows(); ++t) m.row(t).maxCoeff(&out[t]);
  return out;
}

double CrfObjective(const LatentCrf& model, const std::vector<CrfSequence>& sequences, double sigma,
                    Eigen::VectorXd* gradient, CrfNumerator numerator) {
  return Objective(model, sequences).Evaluate(model, sigma, gradient, numerator);
}

void CrfTrainingOptions::Check() const {
  if (!(sigma >= 0) || !std::isfinite(sigma)) throw std::invalid_argument("CRF training: sigma must be >= 0");
  if (max_iterations < 1) throw std::invalid_argument("CRF training: max_iterations must be >= 1");
  if (!(epsilon > 0)) throw std::invalid_argument("CRF training: epsilon must be > 0");
  if (!(init_scale >= 0)) throw std::invalid_argument("CRF training: init_scale must be >= 0");
}

CrfTrainingReport TrainCrf(LatentCrf* model, const std::vector<CrfSequence>& sequences,
                           const CrfTrainingOptions& options) {
  options.Check();
  if (sequences.empty()) throw std::invalid_argument("CRF training needs at least one sequence");
  const Objective objective(*model, sequences);
  // Hidden states of one label start apart, or they would stay identical.
  Eigen::VectorXd theta = Eigen::VectorXd::Zero(model->ParameterCount());
  if (model->states_per_label() > 1) {
    std::mt19937_64 rng(options.seed);
    std::uniform_real_distribution<double> u(-options.init_scale, options.init_scale);
    for (Eigen::Index i = 0; i < theta.size(); ++i) theta(i) = u(rng);
  }
  const int n = static_cast<int>(theta.size());
  lbfgsfloatval_t* x = lbfgs_malloc(n);
  if (!x) throw std::bad_alloc();
  Eigen::Map<Eigen::VectorXd>(x, n) = theta;
  lbfgs_parameter_t param;
  lbfgs_parameter_init(&param);
  param.max_iterations = options.max_iterations;
  param.epsilon = options.epsilon;
  TrainingState state{model, &objective, &options};
  CrfTrainingReport report;
  int iterations = 0;
  const std::function<void(int, double)> user_progress = options.progress;
  CrfTrainingOptions counting = options;
  counting.progress = [&](int k, double fx) {
    iterations = k;
    report.objective = fx;
    if (user_progress) user_progress(k, fx);
  };
  state.options = &counting;
  lbfgsfloatval_t fx = 0;
  report.status = lbfgs(n, x, &fx, EvaluateForLbfgs, ProgressForLbfgs, &state, &param);
  // On an error liblbfgs leaves x at the last accepted point.
  model->SetParameters(Eigen::Map<const Eigen::VectorXd>(x, n));
  lbfgs_free(x);
  report.iterations = iterations;
  report.objective = objective.Evaluate(*model, options.sigma, nullptr, CrfNumerator::kAuto);
  report.status_text = LbfgsStatusText(report.status);
  return report;
}

}  // namespace irbench
