#pragma once
// Posture decomposition (thesis 5.1.1): a shape descriptor as the resting
// posture plus weighted arm atoms, and the recognised [primary, secondary]
// pair of atoms. Steps, each its own function:
//   1. f = the descriptor at unit length; alpha_0 = <f, A0>, R_0 = f - alpha_0 A0
//      (Eq. 5.6), A0 the user's own resting posture when known (UserRest);
//   2. the arm atoms' weights: the thesis's modified matching pursuit (atom
//      with the most overlapping non-empty bins, Eq. 5.7; its weight
//      <R, A_n> over <A_n, A_n>; the overlapping bins removed, Eq. 5.8), or
//      non-negative least squares;
//   3. the pair from the weights (posture_atoms.h, PairRule), agreeing with
//      the pose tracker's rest state where the atoms ask for it.

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "tracker/posture/posture_atoms.h"

namespace irbench {

struct Posture {
  // Per atom, in PostureAtoms::names order: weights[0] = <f, A0>, then the
  // arm atoms' weights (one arm in an atom's posture weighs about 1).
  std::vector<double> weights;
  // The recognised atoms, indices into names, in lexical order (the thesis:
  // "ordered by their lexical precedence"); {0, 0}: the resting posture.
  std::array<int, 2> pair{0, 0};
};

// f - <f, a0> a0 for f the descriptor at unit length and a0 unit length
// (Eq. 5.6); `alpha0` gets <f, a0>. A zero descriptor gives zeros.
std::vector<float> RestResidual(const std::vector<float>& descriptor, const std::vector<float>& a0, double* alpha0);

// The thesis's modified matching pursuit over `arms` (Eqs. 5.7-5.8, 5.10):
// up to `iterations` atoms, each chosen once, by the count of bins above
// `overlap_threshold` in both the residual and the atom; weight <R, A> /
// <A, A>; then the overlapping bins are removed from the residual. Stops when
// no atom overlaps. Returns one weight per arm atom (0: not chosen).
std::vector<double> MatchingPursuitWeights(const std::vector<float>& residual,
                                           const std::vector<std::vector<float>>& arms, int iterations,
                                           double overlap_threshold);

// argmin over w >= 0 of |residual - sum_k w_k arms[k]|^2, exactly (every
// subset of atoms solved by its normal equations; up to 10 atoms).
std::vector<double> NonNegativeWeights(const std::vector<float>& residual, const std::vector<std::vector<float>>& arms);

// The pair from the arm atoms' weights by the atoms' rule. `arms_at_rest`:
// how many arms (0-2) the pose tracker's rest-state classifier finds at rest,
// when it has an answer; with atoms.pair_rest_state the rule then chooses
// only among pairs with that many A0s (the centroids of such pairs; the
// thresholds rule takes the 2 - n heaviest atoms, one twice when it weighs
// `instance` or the next is under `presence`). Without an answer, or when no
// centroid has that many A0s, the weights alone decide.
std::array<int, 2> PairFromWeights(const std::vector<double>& arm_weights, const PostureAtoms& atoms,
                                   std::optional<int> arms_at_rest = std::nullopt);

// "A1+A3": a pair's name, its atoms' names in order.
std::string PairName(const std::array<int, 2>& pair, const PostureAtoms& atoms);

// Steps 1-3. `user_rest`: the user's resting posture at unit length, or
// empty for the atoms' A0; `arms_at_rest` as PairFromWeights. Throws
// std::invalid_argument when the descriptor does not have the atoms' bin
// count.
Posture DecomposePosture(const std::vector<float>& descriptor, const std::vector<float>& user_rest,
                         const PostureAtoms& atoms, std::optional<int> arms_at_rest = std::nullopt);

// A user's resting posture: the running mean of their unit-length
// descriptors on frames the tracker finds both arms at rest (the rest-state
// classifier, thesis 6.4), over about the last `frames` such frames.
class UserRest {
 public:
  explicit UserRest(int frames = 60) : frames_(frames) {}
  void Update(const std::vector<float>& descriptor, bool both_arms_at_rest);
  // Unit length; empty until a frame at rest was seen.
  const std::vector<float>& Current() const { return unit_; }
  int seen() const { return seen_; }

 private:
  int frames_;
  int seen_ = 0;
  std::vector<double> mean_;
  std::vector<float> unit_;
};

}  // namespace irbench
