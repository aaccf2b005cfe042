#pragma once
// Online motion labelling (thesis 7.1) frame by frame: each frame's features
// per arm, and its labels once the `window` frames after it are in, so the
// latency is the model's window (10 frames: 1/3 s at 30 fps). The labels of
// frame t are the largest marginals of a forward-backward pass over the
// frames tracked from t - history to t + window (the chain's edges beyond
// that are cut; docs/recognition.md compares it with the whole sequence's
// pass). A frame without a tracked person ends the segment: its pending
// frames get their labels at once (the window's edge frames repeated).

#include <array>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "tracker/motion_labels/motion_features.h"
#include "tracker/motion_labels/motion_label_model.h"

namespace irbench {

class MotionLabeler {
 public:
  explicit MotionLabeler(std::shared_ptr<const MotionLabelModel> model, int history = 30);

  struct Labels {
    int frame = 0;
    std::optional<std::array<std::string, 2>> arms;  // right, left; none where nobody was tracked
  };
  // Frame `frame` (increasing) and its observation, nullopt where nobody is
  // tracked. Returns the frames whose labels are final now, in order.
  std::vector<Labels> Update(int frame, const std::optional<MotionObservation>& observation);
  // The frames still pending at the end of the input.
  std::vector<Labels> Finish();

  int latency_frames() const { return model_->crf.window(); }
  const MotionLabelModel& model() const { return *model_; }

 private:
  // Labels pending frame `index` (into segment_) from the segment so far.
  Labels LabelAt(size_t index) const;
  void EmitThrough(size_t end, std::vector<Labels>* out);

  std::shared_ptr<const MotionLabelModel> model_;
  int history_;
  MotionFeatureExtractor extractor_;
  std::vector<int> frames_;                            // the segment's frames
  std::array<std::vector<MotionFeatures>, 2> arms_;    // their features per arm
  size_t next_ = 0;                                    // first frame not yet labelled
  std::optional<int> last_frame_;
};

}  // namespace irbench
