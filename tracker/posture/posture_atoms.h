#pragma once
// The posture atoms (thesis 5.1): the dictionary a posture's shape descriptor
// is decomposed over, learned from rendered training sequences (`irbench
// train atoms`, ci/train/atom_training.h) and stored as a versioned model
// file, irbench.posture-atoms/1 (JSON; docs/recognition.md):
//
//   A0, the resting posture: the mean unit-length descriptor of the training
//       persons standing with both arms at rest. A user's own resting
//       descriptor, once the tracker has seen them at rest, replaces it
//       (UserRest, decompose.h): the torso and legs are most of the
//       descriptor, and they differ more between persons than arms do.
//   A1..A4, the arm atoms: the mean over one-arm training frames of the
//       descriptor's part that is not the rest posture, f - <f, A0> A0
//       (thesis Eq. 5.6), scaled so that one arm in the atom's posture
//       weighs 1 (the thesis's alpha'_i, "the average weight" of a one-atom
//       posture).
//   The decision rule from weights to the [primary, secondary] pair, and its
//   learned parameters.

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "tracker/shape/shape_descriptor.h"

namespace irbench {

// How the weights of the arm atoms are found (decompose.h).
enum class AtomWeights {
  kMatchingPursuit,  // the thesis's modified matching pursuit (5.1.1): atoms by bin overlap
  kNonNegative,      // non-negative least squares over all arm atoms at once
};
// How the pair follows from the weights.
enum class PairRule {
  kThresholds,  // the thesis's: atoms above `presence`, two instances above `instance`
  kCentroids,   // the nearest of the training pairs' mean weight vectors (linear discriminants)
};

const char* AtomWeightsName(AtomWeights w);
const char* PairRuleName(PairRule r);

struct PostureAtoms {
  static constexpr const char* kFormat = "irbench.posture-atoms/1";

  ShapeDescriptorOptions descriptor;  // what the atoms were computed with
  std::vector<std::string> names;     // names[0] the rest posture ("A0"), then the arm atoms
  std::vector<float> rest;            // A0, unit length
  std::vector<std::vector<float>> arms;  // arms[k - 1]: atom k's arm part
  AtomWeights weights = AtomWeights::kNonNegative;
  int iterations = 3;               // matching pursuit's
  double overlap_threshold = 1e-3;  // a bin takes part in an overlap above this
  PairRule rule = PairRule::kCentroids;
  double presence = 0.4;  // thresholds rule: an atom is present at this weight
  double instance = 1.3;  // ... and twice present at this one
  // Centroids rule: per pair ("A1+A3", names in order), its mean arm-atom
  // weights over the training frames.
  std::vector<std::pair<std::string, std::vector<double>>> centroids;
  // ... and the distance to them: Mahalanobis with this precision (the
  // inverse of the pairs' pooled within-pair covariance of the weights; K x K
  // row-major, K the arm atoms), Euclidean when empty.
  std::vector<double> centroid_precision;
  // Whether the pair agrees with the pose tracker's rest state (thesis 6.4)
  // where it has one: as many A0s in the pair as arms it finds at rest, the
  // rule choosing only among those pairs (decompose.h). Two arms in one atom
  // weigh 1.3-1.8 on the tracker's hulls, not 2, and an arm hanging
  // diagonally down is close to rest in the descriptor; the rest state tells
  // both apart. Files without the key predate it: false.
  bool pair_rest_state = false;
  nlohmann::json provenance;  // how the file was made

  int atom_count() const { return static_cast<int>(names.size()); }
  // Throws InputError naming `file` and the field when the parts disagree.
  void Check(const std::string& file = "") const;

  // Throws InputError naming the file and field on anything malformed, of
  // another format, or whose vectors do not have the descriptor's bin count.
  static PostureAtoms Load(const std::filesystem::path& path);
  void Save(const std::filesystem::path& path) const;  // atomic
};

// Where the tracker finds the atoms by default: tracker/models/posture_atoms.json
// under the data root.
std::filesystem::path DefaultPostureAtomsPath();

}  // namespace irbench
