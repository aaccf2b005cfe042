#pragma once
// `irbench train gestures`: trains the gesture models (thesis 5.2,
// tracker/gesture/gesture_models.h) from rendered gesture sessions
// (motions/gesture_set.json) and scores them the thesis's way (5.3): every
// gesture the truth's events mark in a test sequence is one segment, put to
// each gesture's model; the most likely is the recognised gesture. Table 5.2
// is the identification rate per gesture and person. A segment is the
// truth's span cut as the online recogniser cuts a performance (the last
// frame at rest before the first with an arm raised, to the last such
// frame), in training and in testing.
//
// Training sees each sequence as the tracker saw it (front end, pose,
// posture decomposition with the given atoms), errors included; the truth
// gives only the gestures' spans. A sequence's `track/` (what `irbench track
// SEQ` writes) is used when it is a pose-stage track of all its frames made
// with the same posture atoms (track.json's models.posture_atoms.sha256); its
// weights are track.jsonl's, rounded to 4 decimals. Otherwise, or with
// `retrack`, the tracker runs on the sequence here.

#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "tracker/gesture/gesture_models.h"

namespace irbench {

struct GestureTrainingJob {
  std::vector<std::filesystem::path> train;  // rendered gesture sessions
  std::vector<std::filesystem::path> test;   // scored with the models trained on `train`
  // Instead of `test`: leave each training sequence out in turn, train on the
  // rest, test on it (the models written are still those of all of `train`).
  bool leave_one_out = false;
  std::filesystem::path posture_atoms;  // default: DefaultPostureAtomsPath()
  std::filesystem::path out;            // default: DefaultGestureModelsPath()
  std::filesystem::path table;          // when set: the tables as Markdown
  bool retrack = false;                 // track every sequence even when its track/ will do
  GestureTrainingOptions options;
};

// Identification counts: kind -> person (the sequence's avatar) -> gesture
// -> {right, total}; and the confusion per kind: truth -> recognised -> count.
struct GestureEvaluation {
  std::map<std::string, std::map<std::string, std::map<std::string, std::pair<int, int>>>> counts;
  std::map<std::string, std::map<std::string, std::map<std::string, int>>> confusion;
  std::vector<std::string> gestures;
  // The mean over persons of each person's mean identification rate.
  double MeanRate(const std::string& kind) const;
  // Table 5.2 per kind (gestures as rows, persons as columns, the thesis's
  // FHMM and HMM figures beside ours), and the confusion matrices.
  std::string Markdown() const;
};

struct GestureTrainingResult {
  std::filesystem::path model;
  int segments = 0;
  // Per sequence (folder name): "track/" or "tracked by irbench train gestures".
  std::map<std::string, std::string> tracks;
  GestureEvaluation evaluation;  // empty without test sequences or leave_one_out
};

// Throws InputError naming the sequence for one without gesture events.
GestureTrainingResult RunGestureTraining(const GestureTrainingJob& job);

}  // namespace irbench
