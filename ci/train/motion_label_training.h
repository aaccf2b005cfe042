#pragma once
// `irbench train motion-labels`: trains the motion-label models (thesis 7.1,
// tracker/motion_labels/) — the CRF and the LDCRF — from rendered sequences
// as the tracker tracked them, so training sees the tracker's errors: each
// sequence's track is its `track/` folder when that holds a pose-stage track
// of all its frames (what `irbench track SEQ` writes), else the tracker runs
// on it here. The truth gives only the labels (labels.motion per arm). With
// test sequences, the confusion matrices of Tables 7.1-7.2 from the online
// labeller, exactly what `irbench track` would write.

#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "tracker/motion_labels/latent_crf.h"
#include "tracker/motion_labels/motion_label_model.h"

namespace irbench {

struct MotionLabelTrainingJob {
  std::vector<std::filesystem::path> train;  // rendered sequences
  std::vector<std::filesystem::path> test;   // scored with the models trained on `train`
  std::vector<MotionModelKind> kinds = {MotionModelKind::kCrf, MotionModelKind::kLdcrf};
  std::filesystem::path out_dir;     // default: tracker/models (motion_crf.json, motion_ldcrf.json)
  std::filesystem::path table;       // when set: the tables as Markdown
  std::filesystem::path rest_model;  // default: DefaultRestModelPath()
  int window = 10;                   // thesis 7.2: 10 frames before and after
  int ldcrf_states = 2;              // thesis 7.2: 2 hidden states per label
  bool retrack = false;              // track every sequence even when it has a track
  MotionDecision decision = MotionDecision::kBalanced;
  double prior_power = 1.0;
  CrfTrainingOptions options;
};

struct MotionLabelEvaluation {
  int frames = 0;  // test frames with a truth label (per arm: twice)
  // kind -> truth -> found -> count, both arms; frames without a tracked
  // person count under found "none".
  std::map<std::string, std::map<std::string, std::map<std::string, int>>> confusion;
  std::string Markdown() const;
};

struct MotionLabelTrainingResult {
  std::vector<std::filesystem::path> models;
  int train_frames = 0;  // arm-frames trained on
  std::map<std::string, CrfTrainingReport> reports;
  std::map<std::string, double> train_seconds;
  MotionLabelEvaluation evaluation;  // empty without test sequences
};

// Throws InputError naming the file for a sequence without motion labels.
MotionLabelTrainingResult RunMotionLabelTraining(const MotionLabelTrainingJob& job);

}  // namespace irbench
