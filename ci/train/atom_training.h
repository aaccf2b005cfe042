#pragma once
// `irbench train atoms`: learns the posture atoms (thesis 5.1,
// tracker/posture/posture_atoms.h) from rendered training sequences — the
// atom tour (every two-arm atom posture in turn) on training persons. Each
// sequence is run through the tracker's front end (the tracker's own
// descriptors, with its errors); the truth's posture labels say which frames
// show which pair and when both arms rest. The tracker later reads only the
// model file (architecture.md: learned parts come from other sequences'
// truth).
//
//   1. per sequence (one person): the person's resting posture, the mean
//      unit descriptor over frames with both arms at rest;
//   2. the arm atoms A1..A4: the mean rest residual (Eq. 5.6) over one-arm
//      frames of every person, scaled so one arm weighs 1 on average;
//   3. the pair rule's parameters: the centroid of every pair's weights, the
//      thresholds by the best training accuracy.
// Leave-one-sequence-out accuracy is reported beside the training accuracy.

#include <filesystem>
#include <string>
#include <vector>

#include "tracker/posture/posture_atoms.h"

namespace irbench {

struct AtomTrainingOptions {
  std::vector<std::filesystem::path> sequences;  // rendered with truth (one person each)
  std::filesystem::path out;                     // default: DefaultPostureAtomsPath()
  AtomWeights weights = AtomWeights::kNonNegative;
  PairRule rule = PairRule::kCentroids;
  bool cross_validate = true;  // leave each sequence out once
};

struct AtomTrainingResult {
  std::filesystem::path model;
  int frames = 0;               // frames with a descriptor and a truth pair
  double training_accuracy = 0;  // pairs right on the training frames
  // Per sequence left out: its name and the accuracy of the atoms learned
  // from the others (empty without cross_validate or with one sequence).
  std::vector<std::pair<std::string, double>> held_out;
};

// Throws InputError naming the sequence for one without truth postures, a
// person never seen at rest, or no one-arm frames of some atom.
AtomTrainingResult RunAtomTraining(const AtomTrainingOptions& options);

}  // namespace irbench
