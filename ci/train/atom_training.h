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

#include <Eigen/Core>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "tracker/posture/posture_atoms.h"

namespace irbench {

struct AtomTrainingOptions {
  std::vector<std::filesystem::path> sequences;  // rendered with truth (one person each)
  // Renders of the 30 candidate postures (irbench render --motion
  // posture_candidates), one person each: when given, the thesis's selection
  // among them (5.1.2, atom_selection.h) is made and reported beside the
  // trained atoms, each candidate named by the truth's atom for its posture.
  // The atoms stay the truth's: its posture labels, and so the scores, name
  // A1..A4 by elevation bands that no selection among postures knows.
  std::vector<std::filesystem::path> candidates;
  std::filesystem::path selection_table;  // the selection as Markdown (with candidates)
  std::filesystem::path out;                     // default: DefaultPostureAtomsPath()
  AtomWeights weights = AtomWeights::kNonNegative;
  PairRule rule = PairRule::kCentroids;
  // The tracker's pair agrees with its rest state (PostureAtoms::pair_rest_state).
  // The accuracies below are the descriptor's alone: the training sequences
  // are not pose-tracked.
  bool pair_rest_state = true;
  bool cross_validate = true;  // leave each sequence out once
};

// What the selection among candidate postures found.
struct AtomSelectionSummary {
  struct Candidate {
    std::string name;   // C01..C30, the render's event value
    std::string about;  // the library's description of the arm
    int atom = 0;       // the truth's atom for it (the other arm rests): 1..4, 0 at rest
  };
  std::vector<Candidate> candidates;
  Eigen::MatrixXd weights;  // M (atom_selection.h)
  Eigen::VectorXd singular_values;
  std::vector<int> selected;  // indices into candidates, in pivot order
  bool one_per_atom = false;  // the selected candidates name A1..A4 once each
  // The share of the unit candidates' norm outside the span of: the selected
  // candidates; the trained (truth's) arm atoms; the SVD's best rank-k
  // subspace. And the largest cosine between two selected candidates, two atoms.
  double selected_residual = 0, atoms_residual = 0, best_residual = 0;
  double selected_overlap = 0, atoms_overlap = 0;
  // The singular values, the selection and M, as Markdown tables.
  std::string Markdown() const;
};

struct AtomTrainingResult {
  std::optional<AtomSelectionSummary> selection;  // with candidates
  std::filesystem::path model;
  int frames = 0;               // frames with a descriptor and a truth pair
  double training_accuracy = 0;  // pairs right on the training frames, by the weights alone
  // Per sequence left out: its name and the accuracy of the atoms learned
  // from the others (empty without cross_validate or with one sequence).
  std::vector<std::pair<std::string, double>> held_out;
};

// Throws InputError naming the sequence for one without truth postures, a
// person never seen at rest, or no one-arm frames of some atom.
AtomTrainingResult RunAtomTraining(const AtomTrainingOptions& options);

}  // namespace irbench
