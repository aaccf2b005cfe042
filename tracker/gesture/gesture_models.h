#pragma once
// Gesture models (thesis 5.2): one model per gesture, of three kinds, over
// the posture decomposition's output frame by frame (tracker/posture):
//   hmm    the plain HMM of Table 5.3: 25 states (every primary/secondary
//          atom combination), Gaussian observations of the atom weight
//          vector, one mean per state and a shared full covariance;
//   pahmm  the parallel HMM (5.2.1): two discrete HMMs of 5 states (the
//          atoms), one over the primary atom, one over the secondary, the
//          likelihood their product (Eq. 5.13), starting at rest;
//   fhmm   the factorial HMM (5.2.2): 2 chains x 5 states, the weight vector
//          Gaussian with mean W_1 S_1 + W_2 S_2 and a full covariance.
// The Gaussian models observe one of (GestureObservationKind):
//   weights  the atom weights (the thesis's);
//   pair     the recognised pair as weights: pair_scale on each of its atoms
//            (twice on one atom that holds both arms): the weights an ideal
//            decomposition of that pair would give, at another scale. The
//            pair agrees with the pose tracker's rest state
//            (posture_atoms.h, pair_rest_state) and does not carry a
//            person's own weight levels, which differ between persons more
//            than the atoms' bands do.
// A segment is recognised as the gesture whose model gives it the highest
// likelihood (equal priors, Eq. 5.12). Stored as irbench.gesture-models/1
// (JSON) with how it was made.

#include <array>
#include <cstdint>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "tracker/gesture/fhmm.h"
#include "tracker/gesture/hmm.h"

namespace irbench {

enum class GestureModelKind { kHmm, kParallelHmm, kFactorialHmm };
const char* GestureModelKindName(GestureModelKind kind);
// "hmm", "pahmm", "fhmm"; nullopt for anything else.
std::optional<GestureModelKind> ParseGestureModelKind(const std::string& name);

// What the HMM's and FHMM's Gaussian observation is (see above).
enum class GestureObservationKind { kWeights, kPair };
const char* GestureObservationKindName(GestureObservationKind kind);
// "weights", "pair"; nullopt for anything else.
std::optional<GestureObservationKind> ParseGestureObservationKind(const std::string& name);

// One frame's posture as the gesture models read it.
struct GestureObservation {
  Eigen::VectorXd weights;  // the atom weights, A0 first (Posture::weights)
  int primary = 0;          // the recognised pair: the later atom in lexical order
  int secondary = 0;        // the earlier one (A0 for a one-arm posture)
};

struct GestureTrainingOptions {
  int hmm_states = 25;
  int chain_states = 5;  // per FHMM chain and per PaHMM chain (the atoms)
  int restarts = 3;      // EM from this many seeded starts; the best kept
  int max_iterations = 60;
  double covariance_ridge = 1e-3;  // added to the Gaussian models' covariance diagonal
  double pseudo_count = 0.5;       // the PaHMM's Dirichlet counts (unseen symbols stay possible)
  // The pair: on the thesis protocol's test persons the FHMM identified
  // 92 % of their gestures against 87 % with the weights (docs/recognition.md).
  GestureObservationKind observation = GestureObservationKind::kPair;
  // The pair observation's weight of one arm in an atom. Its spread within
  // a state can be as small as the covariance ridge, so the scale sets what
  // one frame whose pair disagrees costs (up to scale^2 / ridge nats).
  double pair_scale = 0.1;
  uint64_t seed = 1;
};

struct GestureModels {
  static constexpr const char* kFormat = "irbench.gesture-models/1";

  std::vector<std::string> gestures;
  std::vector<std::string> atoms;  // the posture atoms' names (the observation's order)
  GestureObservationKind observation = GestureObservationKind::kWeights;
  double pair_scale = 0.1;  // the pair observation's (GestureTrainingOptions)
  std::vector<GaussianHmm> hmm;
  std::vector<std::array<DiscreteHmm, 2>> pahmm;  // primary, secondary
  std::vector<Fhmm> fhmm;
  nlohmann::json provenance;

  int gesture_count() const { return static_cast<int>(gestures.size()); }
  // The observation's size: one value per atom (weights or pair alike).
  int dimension() const { return static_cast<int>(atoms.size()); }

  // One frame's observation as the Gaussian models read it (dimension()
  // values). Throws std::invalid_argument for weights of another size.
  Eigen::VectorXd ObservationVector(const GestureObservation& o) const;

  // log p(segment | gesture g's model of `kind`). Throws std::invalid_argument
  // for an observation of another dimension or atom index.
  double LogLikelihood(GestureModelKind kind, int g, const std::vector<GestureObservation>& segment) const;
  // The most likely gesture (index) and every gesture's log-likelihood.
  int Classify(GestureModelKind kind, const std::vector<GestureObservation>& segment,
               std::vector<double>* log_likelihoods = nullptr) const;

  // Trains all three kinds. `segments[g]`: gesture g's training segments
  // (each non-empty). Throws std::invalid_argument on a gesture without one.
  static GestureModels Train(const std::vector<std::string>& gestures, const std::vector<std::string>& atoms,
                             const std::vector<std::vector<std::vector<GestureObservation>>>& segments,
                             const GestureTrainingOptions& options);

  // Throws InputError naming the file and field on anything malformed, of
  // another format or of sizes that disagree (a model trained for another
  // number of atoms).
  static GestureModels Load(const std::filesystem::path& path);
  void Save(const std::filesystem::path& path) const;  // atomic
};

// Where the tracker finds the gesture models by default:
// tracker/models/gesture_models.json under the data root.
std::filesystem::path DefaultGestureModelsPath();

}  // namespace irbench
