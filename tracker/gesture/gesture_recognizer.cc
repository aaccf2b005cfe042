#include "tracker/gesture/gesture_recognizer.h"

#include <algorithm>
#include <limits>
#include <stdexcept>

namespace irbench {

GestureRecognizer::GestureRecognizer(std::shared_ptr<const GestureModels> models, GestureModelKind kind,
                                     GestureRecognizerOptions options)
    : models_(std::move(models)), options_(options) {
  if (!models_) throw std::invalid_argument("GestureRecognizer needs models");
  for (int g = 0; g < models_->gesture_count(); ++g) {
    switch (kind) {
      case GestureModelKind::kHmm: {
        streams_.push_back(Stream{.gesture = g,
                                  .chain = models_->hmm[g].chain,
                                  .means = models_->hmm[g].means,
                                  .covariance = models_->hmm[g].covariance});
        break;
      }
      case GestureModelKind::kFactorialHmm: {
        const Fhmm& f = models_->fhmm[g];
        streams_.push_back(
            Stream{.gesture = g, .chain = f.ProductChain(), .means = f.ProductMeans(), .covariance = f.covariance});
        break;
      }
      case GestureModelKind::kParallelHmm:
        for (int c = 0; c < 2; ++c) {
          streams_.push_back(Stream{.gesture = g,
                                    .chain = models_->pahmm[g][c].chain,
                                    .log_emission = models_->pahmm[g][c].log_emission,
                                    .primary = c == 0});
        }
        break;
    }
  }
}

bool BothArmsAtRest(std::optional<bool> right, std::optional<bool> left,
                    const std::optional<GestureObservation>& posture) {
  if (right && left) return *right && *left;
  return posture && posture->primary == 0 && posture->secondary == 0;
}

Eigen::VectorXd GestureRecognizer::EmissionOf(const Stream& s, const GestureObservation& o,
                                              std::optional<Eigen::VectorXd>& y) const {
  if (s.means.size() == 0) {
    const int symbol = s.primary ? o.primary : o.secondary;
    if (symbol < 0 || symbol >= s.log_emission.cols()) throw std::invalid_argument("an atom outside the models'");
    return s.log_emission.col(symbol);
  }
  if (!y) y = models_->ObservationVector(o);
  return GaussianLogDensities(*y, s.means, s.covariance).row(0).transpose();
}

void GestureRecognizer::Advance(const GestureObservation& o) {
  log_likelihoods_.assign(models_->gesture_count(), 0.0);
  std::optional<Eigen::VectorXd> y;
  for (Stream& s : streams_) {
    const Eigen::VectorXd e = EmissionOf(s, o, y);
    if (frames_ == 0) {
      s.log_alpha = s.chain.log_initial + e;
    } else {
      Eigen::VectorXd next(s.chain.size());
      for (int j = 0; j < s.chain.size(); ++j) next(j) = LogSumExp(s.log_alpha + s.chain.log_transition.col(j)) + e(j);
      s.log_alpha.swap(next);
    }
    log_likelihoods_[s.gesture] += LogSumExp(s.log_alpha);
  }
  ++frames_;
}

std::optional<GestureDecision> GestureRecognizer::Update(int frame, const std::optional<GestureObservation>& observation,
                                                         bool at_rest) {
  if (!observation || at_rest) {
    in_segment_ = false;
    frames_ = 0;
    log_likelihoods_.clear();
    if (observation) last_at_rest_ = observation;
    if (!observation) last_at_rest_.reset();
    return std::nullopt;
  }
  if (!in_segment_) {
    in_segment_ = true;
    start_frame_ = frame;
    frames_ = 0;
    if (last_at_rest_) Advance(*last_at_rest_);
  }
  Advance(*observation);
  if (frames_ < options_.min_frames) return std::nullopt;
  std::vector<double> sorted = log_likelihoods_;
  const int best = static_cast<int>(std::max_element(log_likelihoods_.begin(), log_likelihoods_.end()) -
                                    log_likelihoods_.begin());
  std::sort(sorted.rbegin(), sorted.rend());
  GestureDecision d;
  d.gesture = best;
  d.start_frame = start_frame_;
  d.frames = frames_;
  d.score = sorted.size() > 1 ? (sorted[0] - sorted[1]) / frames_ : 0.0;
  if (!std::isfinite(d.score)) d.score = std::numeric_limits<double>::max();
  return d;
}

}  // namespace irbench
