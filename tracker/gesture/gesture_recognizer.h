#pragma once
// Online gesture recognition (thesis 5.2, frame by frame). The decision rule:
//   - a segment starts at the first frame whose arms are not both at rest
//     (the tracker's rest-state classifier) and ends at the next frame at
//     rest; the last frame at rest before it is its first observation (the
//     models start at rest, thesis 5.2.1);
//   - each gesture model's forward variables are advanced one frame at a
//     time (O(states^2) per model and frame), so the segment's
//     log-likelihood under every model is known at every frame;
//   - while the segment runs and has at least `min_frames` observations, the
//     decision is the most likely gesture (equal priors, Eq. 5.12), its
//     score the log-likelihood margin over the runner-up per frame; before
//     that, at rest, and on frames without a posture (empty stage): no
//     gesture.

#include <memory>
#include <optional>
#include <vector>

#include "tracker/gesture/gesture_models.h"

namespace irbench {

struct GestureRecognizerOptions {
  int min_frames = 15;  // half a second at 30 fps
};

struct GestureDecision {
  int gesture = 0;       // index into GestureModels::gestures
  double score = 0;      // (best - runner-up log-likelihood) / frames
  int start_frame = 0;   // the segment's first frame off rest
  int frames = 0;        // observations so far
};

// Both arms at rest as the recogniser is told (FrameTracker) and as gesture
// training cuts its segments: by the rest-state classifier where it judged
// both arms (right, left), else by the recognised pair (A0+A0), else not.
bool BothArmsAtRest(std::optional<bool> right, std::optional<bool> left,
                    const std::optional<GestureObservation>& posture);

class GestureRecognizer {
 public:
  GestureRecognizer(std::shared_ptr<const GestureModels> models, GestureModelKind kind,
                    GestureRecognizerOptions options = {});

  // Frame `frame`: its observation (nullopt: no posture) and whether both
  // arms are at rest. Returns the current decision, or nullopt.
  std::optional<GestureDecision> Update(int frame, const std::optional<GestureObservation>& observation,
                                        bool at_rest);

  // The running segment's log-likelihood under each gesture (empty outside one).
  const std::vector<double>& log_likelihoods() const { return log_likelihoods_; }

 private:
  // One chain of one gesture's model and how it scores a frame.
  struct Stream {
    // Every member initialised here: the constructor names only those its
    // kind of model uses.
    int gesture = 0;
    LogMarkovChain chain{};
    Eigen::MatrixXd means{};         // Gaussian: D x N (empty for a discrete chain)
    Eigen::MatrixXd covariance{};    // Gaussian
    Eigen::MatrixXd log_emission{};  // discrete: N x symbols
    bool primary = true;             // discrete: which atom it reads
    Eigen::VectorXd log_alpha{};     // the forward variables so far
  };
  // `y`: the frame's Gaussian observation, made on the first stream that needs it.
  Eigen::VectorXd EmissionOf(const Stream& s, const GestureObservation& o, std::optional<Eigen::VectorXd>& y) const;
  void Advance(const GestureObservation& o);

  std::shared_ptr<const GestureModels> models_;
  GestureRecognizerOptions options_;
  std::vector<Stream> streams_;
  std::optional<GestureObservation> last_at_rest_;
  bool in_segment_ = false;
  int start_frame_ = 0, frames_ = 0;
  std::vector<double> log_likelihoods_;
};

}  // namespace irbench
