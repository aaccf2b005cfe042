#include "tracker/motion_labels/motion_labeler.h"

#include <algorithm>
#include <stdexcept>

namespace irbench {

MotionLabeler::MotionLabeler(std::shared_ptr<const MotionLabelModel> model, int history)
    : model_(std::move(model)), history_(history) {
  if (!model_) throw std::invalid_argument("MotionLabeler needs a model");
  if (history_ < 0) throw std::invalid_argument("MotionLabeler: history must be >= 0");
}

MotionLabeler::Labels MotionLabeler::LabelAt(size_t index) const {
  const size_t begin = index > static_cast<size_t>(history_) ? index - history_ : 0;
  const size_t end = std::min(frames_.size(), index + model_->crf.window() + 1);
  Labels out;
  out.frame = frames_[index];
  std::array<std::string, 2> arms;
  for (int a = 0; a < 2; ++a) {
    const std::vector<MotionFeatures> span(arms_[a].begin() + begin, arms_[a].begin() + end);
    const Eigen::MatrixXd marginals = model_->crf.LabelMarginals(model_->Standardize(span));
    const int best = model_->Decide(marginals.row(static_cast<Eigen::Index>(index - begin)));
    arms[a] = a == 0 ? model_->labels[best] : MirrorMotionLabel(model_->labels[best]);
  }
  out.arms = arms;
  return out;
}

void MotionLabeler::EmitThrough(size_t end, std::vector<Labels>* out) {
  for (; next_ < end; ++next_) out->push_back(LabelAt(next_));
  // Keep what the next labels' history needs.
  const size_t keep_from = next_ > static_cast<size_t>(history_) ? next_ - history_ : 0;
  if (keep_from > 0) {
    frames_.erase(frames_.begin(), frames_.begin() + keep_from);
    for (auto& a : arms_) a.erase(a.begin(), a.begin() + keep_from);
    next_ -= keep_from;
  }
}

std::vector<MotionLabeler::Labels> MotionLabeler::Update(int frame, const std::optional<MotionObservation>& observation) {
  if (last_frame_ && frame <= *last_frame_) throw std::invalid_argument("MotionLabeler: frames must increase");
  last_frame_ = frame;
  std::vector<Labels> out;
  const std::optional<std::array<MotionFeatures, 2>> features = extractor_.Update(observation);
  if (!features) {
    out = Finish();
    out.push_back(Labels{frame, std::nullopt});
    return out;
  }
  frames_.push_back(frame);
  for (int a = 0; a < 2; ++a) arms_[a].push_back((*features)[a]);
  const size_t window = static_cast<size_t>(model_->crf.window());
  if (frames_.size() > window) EmitThrough(frames_.size() - window, &out);
  return out;
}

std::vector<MotionLabeler::Labels> MotionLabeler::Finish() {
  std::vector<Labels> out;
  EmitThrough(frames_.size(), &out);
  frames_.clear();
  for (auto& a : arms_) a.clear();
  next_ = 0;
  return out;
}

}  // namespace irbench
