#pragma once
// Selecting the posture atoms among candidate postures (thesis 5.1.2): each
// candidate decomposed by matching pursuit with each other candidate as its
// only atom gives the weight matrix M (the thesis's Fig. 5.1); its singular
// values (Fig. 5.2) say how many distinct postures the candidates hold, and
// the atoms are the candidates that span M's dominant singular subspace.
//
// The thesis says only that "from the lower ranked matrix we selected five
// atoms corresponding to the largest eigenvalues". We read that as subset
// selection (Golub, Klema and Stewart 1976; Golub and Van Loan 12.2): V_k,
// the right singular vectors of the k largest singular values, and a QR
// factorisation of V_k' with column pivoting; its first k pivots are the k
// candidates whose columns of V_k' are the most independent, i.e. one
// representative of each of the rank-k approximation's directions, not k
// variants of the strongest one. docs/recognition.md.

#include <Eigen/Core>
#include <vector>

namespace irbench {

struct AtomSelection {
  // M(i, j): the weight of candidate j when candidate i is decomposed by
  // matching pursuit with j as its only atom (one iteration, decompose.h),
  // the candidates at unit length, so M is symmetric with a unit diagonal
  // (where a candidate has bins above the overlap threshold).
  Eigen::MatrixXd weights;
  Eigen::VectorXd singular_values;  // of M, descending
  Eigen::MatrixXd low_rank;         // M's best rank-k approximation (k = selected.size())
  std::vector<int> selected;        // candidate indices, in the order the pivoting chose them
};

// `candidates`: the candidate postures' descriptor parts (for the arm
// atoms: each candidate's mean rest residual, Eq. 5.6), all of one size,
// none zero. Throws std::invalid_argument on sizes that differ, a zero
// candidate, or `count` outside 1..candidates.size().
AtomSelection SelectAtoms(const std::vector<std::vector<float>>& candidates, int count,
                          double overlap_threshold);

}  // namespace irbench
