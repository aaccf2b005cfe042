#include "tracker/posture/atom_selection.h"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <random>
#include <set>
#include <stdexcept>

namespace irbench {
namespace {

TEST(AtomSelection, TheMatrixHoldsMatchingPursuitsWeightsOfUnitCandidates) {
  // Hand-computed: at unit length a = (1, 1, 0, 0) / sqrt 2, b = (0, 1, 1, 0)
  // / sqrt 2, c = (0, 0, 0, 1); <a, b> = 1/2, c overlaps neither. d = (1, -1,
  // 0, 0) / sqrt 2 overlaps a in bin 0, but <d, a> = 0; with b it shares no
  // bin above the threshold (its bin 1 is negative).
  // A threshold of 1.5 is above every unit value: no bins overlap, no weights.
  const std::vector<std::vector<float>> cands = {{1, 1, 0, 0}, {0, 3, 3, 0}, {0, 0, 0, 2}, {1, -1, 0, 0}};
  const AtomSelection s = SelectAtoms(cands, 2, 1e-3);
  const Eigen::Matrix4d expected{{1, 0.5, 0, 0}, {0.5, 1, 0, 0}, {0, 0, 1, 0}, {0, 0, 0, 1}};
  EXPECT_LT((s.weights - expected).cwiseAbs().maxCoeff(), 1e-6) << s.weights;
  EXPECT_EQ(SelectAtoms(cands, 1, 1.5).weights.cwiseAbs().maxCoeff(), 0.0);
}

TEST(AtomSelection, SingularValuesAndTheLowRankMatrixAreMs) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  std::vector<std::vector<float>> cands(12, std::vector<float>(40));
  for (auto& c : cands) {
    for (float& v : c) v = u(rng) < 0.3f ? u(rng) : 0.0f;
    c[0] = 0.5f;  // none empty
  }
  const AtomSelection s = SelectAtoms(cands, 3, 1e-3);
  ASSERT_EQ(s.weights.rows(), 12);
  EXPECT_LT((s.weights - s.weights.transpose()).cwiseAbs().maxCoeff(), 1e-6);
  // M is symmetric (to the descriptors' float precision): its singular values
  // are its eigenvalues' magnitudes.
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(0.5 * (s.weights + s.weights.transpose()));
  std::vector<double> mags;
  for (int i = 0; i < 12; ++i) mags.push_back(std::abs(eig.eigenvalues()(i)));
  std::sort(mags.rbegin(), mags.rend());
  for (int i = 0; i < 12; ++i) EXPECT_NEAR(s.singular_values(i), mags[i], 1e-6);
  // Eckart-Young: the rank-3 approximation leaves the other singular values.
  double rest = 0;
  for (int i = 3; i < 12; ++i) rest += mags[i] * mags[i];
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(s.weights);
  double own = 0;
  for (int i = 3; i < 12; ++i) own += svd.singularValues()(i) * svd.singularValues()(i);
  EXPECT_NEAR((s.weights - s.low_rank).squaredNorm(), own, 1e-9);
  EXPECT_NEAR(own, rest, 1e-6);
}

// 30 candidates around four postures on disjoint bins (10, 8, 7 and 5 of
// them): the four atoms are one of each, and span the rank-4 subspace
// nearly as well as the best of all C(30, 4) subsets (brute force).
TEST(AtomSelection, PicksOneCandidateOfEachDistinctPosture) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<float> u(0.2f, 1.0f);
  const int bins = 200;
  std::vector<std::vector<float>> prototypes(4, std::vector<float>(bins, 0.0f));
  for (int k = 0; k < 4; ++k) {
    for (int i = 50 * k; i < 50 * k + 40; ++i) prototypes[k][i] = u(rng);
  }
  const int sizes[4] = {10, 8, 7, 5};
  std::vector<std::vector<float>> cands;
  std::vector<int> cluster;
  for (int k = 0; k < 4; ++k) {
    for (int m = 0; m < sizes[k]; ++m) {
      std::vector<float> c = prototypes[k];
      // A variant: its own bins jittered, and a little of the block's margin.
      for (int i = 50 * k; i < 50 * k + 50; ++i) c[i] = c[i] * (0.7f + 0.6f * u(rng) - 0.2f) + 0.1f * u(rng);
      cands.push_back(c);
      cluster.push_back(k);
    }
  }
  // Shuffle so order does not decide.
  std::vector<int> order(cands.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = static_cast<int>(i);
  std::shuffle(order.begin(), order.end(), rng);
  std::vector<std::vector<float>> shuffled;
  std::vector<int> shuffled_cluster;
  for (int i : order) shuffled.push_back(cands[i]), shuffled_cluster.push_back(cluster[i]);

  const AtomSelection s = SelectAtoms(shuffled, 4, 1e-3);
  ASSERT_EQ(s.selected.size(), 4u);
  std::set<int> clusters;
  for (int i : s.selected) clusters.insert(shuffled_cluster[i]);
  EXPECT_EQ(clusters.size(), 4u) << "two atoms from one posture";
  // Four distinct postures: four singular values well above the rest.
  EXPECT_GT(s.singular_values(3), 5 * s.singular_values(4));

  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(s.weights, Eigen::ComputeFullV);
  const Eigen::MatrixXd vt = svd.matrixV().leftCols(4).transpose();
  auto volume = [&](const std::vector<int>& cols) {
    Eigen::Matrix4d m;
    for (int c = 0; c < 4; ++c) m.col(c) = vt.col(cols[c]);
    return std::abs(m.determinant());
  };
  double best = 0;
  const int n = static_cast<int>(shuffled.size());
  for (int a = 0; a < n; ++a)
    for (int b = a + 1; b < n; ++b)
      for (int c = b + 1; c < n; ++c)
        for (int d = c + 1; d < n; ++d) best = std::max(best, volume({a, b, c, d}));
  EXPECT_GE(volume(s.selected), 0.5 * best);
}

TEST(AtomSelection, RefusesBadArguments) {
  EXPECT_THROW(SelectAtoms({{1, 0}, {0, 1}}, 0, 1e-3), std::invalid_argument);
  EXPECT_THROW(SelectAtoms({{1, 0}, {0, 1}}, 3, 1e-3), std::invalid_argument);
  EXPECT_THROW(SelectAtoms({{1, 0}, {0, 1, 0}}, 1, 1e-3), std::invalid_argument);
  EXPECT_THROW(SelectAtoms({{1, 0}, {0, 0}}, 1, 1e-3), std::invalid_argument);
}

}  // namespace
}  // namespace irbench
