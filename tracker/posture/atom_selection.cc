#include "tracker/posture/atom_selection.h"

#include <Eigen/QR>
#include <Eigen/SVD>
#include <cmath>
#include <stdexcept>

#include "tracker/posture/decompose.h"

namespace irbench {

AtomSelection SelectAtoms(const std::vector<std::vector<float>>& candidates, int count,
                          double overlap_threshold) {
  const int n = static_cast<int>(candidates.size());
  if (count < 1 || count > n) throw std::invalid_argument("SelectAtoms: count must be 1..candidates");
  std::vector<std::vector<float>> unit;
  for (const std::vector<float>& c : candidates) {
    if (c.size() != candidates.front().size()) throw std::invalid_argument("SelectAtoms: candidate sizes differ");
    double norm = 0;
    for (float v : c) norm += static_cast<double>(v) * v;
    if (norm == 0) throw std::invalid_argument("SelectAtoms: a zero candidate");
    norm = std::sqrt(norm);
    std::vector<float> u(c.size());
    for (size_t i = 0; i < c.size(); ++i) u[i] = static_cast<float>(c[i] / norm);
    unit.push_back(std::move(u));
  }
  AtomSelection s;
  s.weights.resize(n, n);
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      s.weights(i, j) = MatchingPursuitWeights(unit[i], {unit[j]}, 1, overlap_threshold)[0];
    }
  }
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(s.weights, Eigen::ComputeFullU | Eigen::ComputeFullV);
  s.singular_values = svd.singularValues();
  const Eigen::MatrixXd u = svd.matrixU().leftCols(count), v = svd.matrixV().leftCols(count);
  s.low_rank = u * s.singular_values.head(count).asDiagonal() * v.transpose();
  // Subset selection: the pivots of V_k' by column-pivoted QR.
  const Eigen::MatrixXd vt = v.transpose();
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(vt);
  const auto& pivots = qr.colsPermutation().indices();
  for (int i = 0; i < count; ++i) s.selected.push_back(pivots(i));
  return s;
}

}  // namespace irbench
