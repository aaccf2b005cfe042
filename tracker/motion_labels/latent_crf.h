#pragma once
// Linear-chain conditional random fields for frame labelling (thesis 7.1):
// the CRF (7.1.1; Lafferty et al. 2001) and the latent-dynamic CRF (7.1.2;
// Morency et al., CVPR 2007), in one model with `states_per_label` hidden
// states per label (1 is the plain CRF). A frame's state potential is linear
// in its window features — the frame's features and those of `window`
// frames before and after (edge frames repeated), and a bias — and
// consecutive states have a transition potential:
//   p(h | x) = exp(sum_t mu_h_t . x_t^win + sum_t lambda(h_t-1, h_t)) / Z(x),
//   p(y | x) = sum over h with every h_t in H(y_t) of p(h | x)   (Eq. 7.2-7.4).
// Training maximises sum log p(y | x) - |theta|^2 / (2 sigma^2) with L-BFGS
// (liblbfgs); inference takes per frame the label of largest marginal
// (belief propagation, i.e. forward-backward in log space, tracker/gesture/hmm.h).

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace irbench {

// One labelled chain: T x D features and T label indices.
struct CrfSequence {
  Eigen::MatrixXd features;
  std::vector<int> labels;
};

class LatentCrf {
 public:
  LatentCrf() = default;
  // All weights 0. Throws std::invalid_argument for sizes < 1 or window < 0.
  LatentCrf(int labels, int states_per_label, int dims, int window);

  int labels() const { return labels_; }
  int states_per_label() const { return states_per_label_; }
  int states() const { return labels_ * states_per_label_; }
  int dims() const { return dims_; }
  int window() const { return window_; }
  // D * (2 window + 1) + 1 (the bias).
  int window_dims() const { return dims_ * (2 * window_ + 1) + 1; }
  // The label of hidden state `h`.
  int LabelOf(int h) const { return h / states_per_label_; }

  // states x window_dims: row h holds mu_h.
  Eigen::MatrixXd& state_weights() { return state_weights_; }
  const Eigen::MatrixXd& state_weights() const { return state_weights_; }
  // states x states: (i, j) = lambda(h_t-1 = i, h_t = j).
  Eigen::MatrixXd& transition() { return transition_; }
  const Eigen::MatrixXd& transition() const { return transition_; }

  // The parameter vector theta: the state weights row by row, then the
  // transitions row by row.
  int ParameterCount() const;
  Eigen::VectorXd Parameters() const;
  void SetParameters(const Eigen::VectorXd& theta);

  // T x window_dims: each frame's window features (T x D in).
  Eigen::MatrixXd WindowFeatures(const Eigen::MatrixXd& features) const;
  // T x states: the state potentials of T x D features.
  Eigen::MatrixXd StatePotentials(const Eigen::MatrixXd& features) const;
  // T x labels: p(y_t = l | x), by forward-backward over the whole chain.
  Eigen::MatrixXd LabelMarginals(const Eigen::MatrixXd& features) const;
  // Per frame the label of largest marginal (ties to the lower index).
  std::vector<int> Decode(const Eigen::MatrixXd& features) const;

 private:
  int labels_ = 0, states_per_label_ = 1, dims_ = 0, window_ = 0;
  Eigen::MatrixXd state_weights_, transition_;
};

// How the objective gets log p(y | x)'s numerator: the labelled path's
// score (only with one state per label: the CRF) or a forward-backward pass
// restricted to the labels' hidden states (the LDCRF's). kAuto picks the
// path for one state per label.
enum class CrfNumerator { kAuto, kPath, kRestricted };

// The training objective: -sum log p(y | x) + |theta|^2 / (2 sigma^2)
// (sigma <= 0: no regularisation), and its gradient in `gradient` when
// given. Throws std::invalid_argument for sequences whose sizes do not fit
// the model.
double CrfObjective(const LatentCrf& model, const std::vector<CrfSequence>& sequences, double sigma,
                    Eigen::VectorXd* gradient, CrfNumerator numerator = CrfNumerator::kAuto);

struct CrfTrainingOptions {
  double sigma = 0.5;       // the Gaussian prior's standard deviation (thesis: "0.5")
  int max_iterations = 300;
  double epsilon = 1e-5;    // liblbfgs: |g| < epsilon max(1, |theta|)
  double init_scale = 0.1;  // the LDCRF's hidden states start from seeded uniform weights
  uint64_t seed = 1;
  // Called after each L-BFGS iteration with its number and the objective.
  std::function<void(int, double)> progress;
  void Check() const;  // throws std::invalid_argument
};

struct CrfTrainingReport {
  int iterations = 0;
  double objective = 0;
  int status = 0;          // liblbfgs's return code
  std::string status_text;  // what it means
};

// Fits `model` (its sizes as constructed) to `sequences` by L-BFGS.
CrfTrainingReport TrainCrf(LatentCrf* model, const std::vector<CrfSequence>& sequences,
                           const CrfTrainingOptions& options);

}  // namespace irbench
