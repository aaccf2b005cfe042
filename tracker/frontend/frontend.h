#pragma once
// The tracker's front end per frame-set (thesis ch. 3): for every camera, the
// silhouette from its background model, cleaned of shadows. Trained from the
// sequence's empty-stage frames only.

#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "tracker/io/sequence_input.h"
#include "tracker/silhouette/background_model.h"
#include "tracker/silhouette/shadow_removal.h"

namespace irbench {

struct FrontEndOptions {
  BackgroundOptions background;
  ShadowOptions shadow;
  bool remove_shadows = true;
  void Check() const;  // throws std::invalid_argument
};

struct CameraFeatures {
  cv::Mat silhouette;      // CV_8UC1 255/0, shadows removed when asked
  cv::Mat before_shadows;  // the background model's mask
  double light_level = 0;
  int blobs_removed = 0;
};

struct FrameFeatures {
  int frame = 0;
  std::vector<CameraFeatures> cameras;
  double ms_silhouettes = 0;  // wall time of this stage for all cameras
};

class FrontEnd {
 public:
  // Throws InputError when the sequence has no empty-stage frames.
  static FrontEnd Train(const SequenceInput& input, const FrontEndOptions& options);
  // `frames`: one 8-bit image per camera, in the input's camera order.
  FrameFeatures Process(int frame, const std::vector<cv::Mat>& frames) const;

  const FrontEndOptions& options() const { return options_; }

 private:
  FrontEndOptions options_;
  std::vector<BackgroundModel> background_;
  std::vector<ShadowRemover> shadows_;
};

}  // namespace irbench
