#pragma once
// The tracker frame-set by frame-set over a sequence's cameras: which cameras
// to leave out (camera health), the front end, the pose tracker, and the
// lines of features.jsonl and track.jsonl (docs/architecture.md, "Tracker
// output"). `irbench track` writes what it gives; `irbench live` publishes it.

#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "tracker/frontend/camera_health.h"
#include "tracker/frontend/frontend.h"
#include "tracker/io/sequence_input.h"
#include "tracker/nss/nss_skeleton.h"
#include "tracker/pipeline/track_settings.h"
#include "tracker/pose/pose_tracker.h"
#include "tracker/gesture/gesture_recognizer.h"
#include "tracker/motion_labels/motion_labeler.h"
#include "tracker/posture/decompose.h"
#include "tracker/shape/shape_descriptor.h"

namespace irbench {

// The rest-state model the settings name, or the shipped one (pose stage
// only); null, with a warning, when the shipped one is absent. Throws
// InputError for a named model that cannot be read.
std::shared_ptr<const RestClassifier> LoadRestClassifier(const TrackerSettings& settings);

class FrameTracker {
 public:
  // Trains the front end on `input`'s empty-stage frames (which must outlive
  // the tracker); the pose tracker when the settings' stage is pose.
  FrameTracker(const SequenceInput& input,
               const TrackerSettings& settings,
               const FrontEndOptions& front_end_options,
               std::shared_ptr<const RestClassifier> rest_classifier);

  struct Step {
    std::vector<cv::Mat> images;  // as read; black where a camera's frame is missing
    FrameFeatures features;
    std::optional<PoseEstimate> pose;
    // The shape descriptor (thesis 4.3) of the voxel hull, for a user of the
    // pose tracker's height (the hull's top before it has one); nullopt
    // when the stage looks empty.
    std::optional<ShapeDescriptor> shape;
    // Its decomposition into the posture atoms (thesis 5.1.1), when the
    // tracker has atoms and a descriptor.
    std::optional<Posture> posture;
    // The online gesture decision (thesis 5.2), when the tracker has models.
    std::optional<GestureDecision> gesture;
    // The hull's NSS skeleton (thesis 4.4.1), with --nss.
    std::optional<NssSkeleton> nss;
    // Motion labels (thesis 7.1) that became final at this frame-set, for
    // this or earlier frames (the model's window late), in frame order.
    std::vector<MotionLabeler::Labels> motion;
    nlohmann::json features_line;  // features.jsonl's line, with "ms"
    nlohmann::json track_line;     // track.jsonl's line, with "ms"
  };
  // Frame-set `f` as SequenceInput::TryFrameSet read it (`problems` per
  // camera), `dt` s after the last one tracked; warns when a camera's state
  // changes.
  Step Track(int f, std::vector<cv::Mat> images, const std::vector<std::string>& problems, double dt);

  // The motion labels still pending after the last frame-set.
  std::vector<MotionLabeler::Labels> FinishMotion();
  // A track.jsonl "motion" value: {"right", "left"} or null.
  static nlohmann::json MotionJson(const MotionLabeler::Labels& labels);

  double train_ms() const { return train_ms_; }
  // The posture atoms' file in use; empty when posture recognition is off.
  const std::filesystem::path& posture_atoms_path() const { return posture_atoms_path_; }
  // The gesture models' file in use; empty when gesture recognition is off.
  const std::filesystem::path& gesture_models_path() const { return gesture_models_path_; }
  // The motion-label model's file in use, and its labeller; empty / null
  // when motion labelling is off.
  const std::filesystem::path& motion_labels_path() const { return motion_labels_path_; }
  const MotionLabeler* motion_labeler() const { return motion_labeler_ ? &*motion_labeler_ : nullptr; }
  const FrontEnd& front_end() const { return front_end_; }
  // Per camera, how many frame-sets it was left out of, by reason.
  const std::vector<std::map<std::string, int>>& left_out_counts() const { return left_out_counts_; }

 private:
  void LoadMotionLabeler(const TrackerSettings& settings);

  const SequenceInput& input_;
  bool nss_ = false;  // TrackerSettings::nss
  double train_ms_ = 0;
  FrontEnd front_end_;
  std::optional<PoseTracker> pose_tracker_;
  bool posture_proposal_ = false;  // the pose tracker proposes from the recognised posture (p_posture > 0)
  ShapeDescriptorOptions shape_options_;  // the atoms' when there are atoms
  std::filesystem::path posture_atoms_path_;
  std::shared_ptr<const PostureAtoms> posture_atoms_;
  UserRest user_rest_;
  std::filesystem::path gesture_models_path_;
  std::shared_ptr<const GestureModels> gesture_models_;
  std::optional<GestureRecognizer> gesture_recognizer_;
  std::shared_ptr<const RestClassifier> rest_classifier_;
  std::filesystem::path motion_labels_path_;
  std::optional<MotionLabeler> motion_labeler_;
  CameraHealthMonitor health_;
  std::vector<CameraHealth> last_health_;  // per camera, to warn on changes
  std::vector<std::map<std::string, int>> left_out_counts_;
};

}  // namespace irbench
