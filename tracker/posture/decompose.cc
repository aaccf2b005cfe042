#include "tracker/posture/decompose.h"

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>

namespace irbench {
namespace {

double Dot(const std::vector<float>& a, const std::vector<float>& b) {
  double s = 0;
  for (size_t i = 0; i < a.size(); ++i) s += static_cast<double>(a[i]) * b[i];
  return s;
}

int IndexOfName(const PostureAtoms& atoms, const std::string& name) {
  const auto it = std::find(atoms.names.begin(), atoms.names.end(), name);
  return it == atoms.names.end() ? -1 : static_cast<int>(it - atoms.names.begin());
}

std::array<int, 2> Ordered(int a, int b) { return {std::min(a, b), std::max(a, b)}; }

}  // namespace

std::vector<float> RestResidual(const std::vector<float>& descriptor, const std::vector<float>& a0, double* alpha0) {
  const double norm = std::sqrt(Dot(descriptor, descriptor));
  std::vector<float> r(descriptor.size(), 0.0f);
  *alpha0 = 0;
  if (norm == 0) return r;
  *alpha0 = Dot(descriptor, a0) / norm;
  for (size_t i = 0; i < r.size(); ++i) r[i] = static_cast<float>(descriptor[i] / norm - *alpha0 * a0[i]);
  return r;
}

std::vector<double> MatchingPursuitWeights(const std::vector<float>& residual,
                                           const std::vector<std::vector<float>>& arms, int iterations,
                                           double overlap_threshold) {
  std::vector<float> r = residual;
  std::vector<double> w(arms.size(), 0.0);
  std::vector<bool> chosen(arms.size(), false);
  const float tau = static_cast<float>(overlap_threshold);
  for (int n = 0; n < iterations; ++n) {
    // Eq. 5.7: the atom overlapping the residual's non-empty bins most.
    int best = -1;
    long best_overlap = 0;
    for (size_t k = 0; k < arms.size(); ++k) {
      if (chosen[k]) continue;
      long overlap = 0;
      for (size_t i = 0; i < r.size(); ++i) overlap += (r[i] > tau && arms[k][i] > tau);
      if (overlap > best_overlap) best_overlap = overlap, best = static_cast<int>(k);
    }
    if (best < 0) break;
    chosen[best] = true;
    const std::vector<float>& a = arms[best];
    w[best] = std::max(0.0, Dot(r, a) / Dot(a, a));
    // Eq. 5.8: the overlapping bins leave the residual.
    for (size_t i = 0; i < r.size(); ++i) {
      if (r[i] > tau && a[i] > tau) r[i] = 0;
    }
  }
  return w;
}

std::vector<double> NonNegativeWeights(const std::vector<float>& residual, const std::vector<std::vector<float>>& arms) {
  const int k = static_cast<int>(arms.size());
  if (k > 10) throw std::invalid_argument("NonNegativeWeights: at most 10 atoms");
  Eigen::MatrixXd gram(k, k);
  Eigen::VectorXd b(k);
  for (int i = 0; i < k; ++i) {
    b(i) = Dot(arms[i], residual);
    for (int j = 0; j <= i; ++j) gram(i, j) = gram(j, i) = Dot(arms[i], arms[j]);
  }
  // |r - A w|^2 = |r|^2 - 2 b'w + w'Gw: the best feasible subset solution.
  std::vector<double> best(k, 0.0);
  double best_cost = 0;  // the empty subset: w = 0
  for (int mask = 1; mask < (1 << k); ++mask) {
    std::vector<int> s;
    for (int i = 0; i < k; ++i) {
      if (mask & (1 << i)) s.push_back(i);
    }
    const int m = static_cast<int>(s.size());
    Eigen::MatrixXd g(m, m);
    Eigen::VectorXd bs(m);
    for (int i = 0; i < m; ++i) {
      bs(i) = b(s[i]);
      for (int j = 0; j < m; ++j) g(i, j) = gram(s[i], s[j]);
    }
    const Eigen::LDLT<Eigen::MatrixXd> ldlt(g);
    if (ldlt.info() != Eigen::Success || !ldlt.isPositive()) continue;
    const Eigen::VectorXd ws = ldlt.solve(bs);
    if (!ws.allFinite() || (ws.array() < 0).any()) continue;
    const double cost = -2 * bs.dot(ws) + ws.dot(g * ws);
    if (cost < best_cost) {
      best_cost = cost;
      std::fill(best.begin(), best.end(), 0.0);
      for (int i = 0; i < m; ++i) best[s[i]] = ws(i);
    }
  }
  return best;
}

std::array<int, 2> PairFromWeights(const std::vector<double>& arm_weights, const PostureAtoms& atoms,
                                   std::optional<int> arms_at_rest) {
  // How many A0s the pair must hold; -1: any.
  const int rests = atoms.pair_rest_state && arms_at_rest ? std::clamp(*arms_at_rest, 0, 2) : -1;
  if (atoms.rule == PairRule::kCentroids) {
    double best = std::numeric_limits<double>::infinity();
    std::array<int, 2> pair{0, 0};
    for (int pass = rests < 0 ? 1 : 0; pass < 2 && best == std::numeric_limits<double>::infinity(); ++pass) {
      for (const auto& [name, centroid] : atoms.centroids) {
        const size_t plus = name.find('+');
        const int a = IndexOfName(atoms, name.substr(0, plus));
        const int b = plus == std::string::npos ? 0 : IndexOfName(atoms, name.substr(plus + 1));
        if (a < 0 || b < 0) continue;
        // Pass 0 keeps to the pairs with the rest state's count of A0s.
        if (pass == 0 && (a == 0) + (b == 0) != rests) continue;
        double d = 0;
        const size_t n = centroid.size();
        if (atoms.centroid_precision.size() == n * n) {
          for (size_t i = 0; i < n; ++i) {
            for (size_t j = 0; j < n; ++j) {
              d += (arm_weights[i] - centroid[i]) * atoms.centroid_precision[i * n + j] * (arm_weights[j] - centroid[j]);
            }
          }
        } else {
          for (size_t k = 0; k < n; ++k) d += (arm_weights[k] - centroid[k]) * (arm_weights[k] - centroid[k]);
        }
        if (d >= best) continue;
        best = d;
        pair = Ordered(a, b);
      }
    }
    return pair;
  }
  // Thresholds: the heaviest atoms present, twice when heavy enough.
  std::vector<int> order(arm_weights.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return arm_weights[a] > arm_weights[b]; });
  std::vector<int> present;
  if (rests >= 0) {
    // The 2 - rests heaviest, the first twice when it weighs two arms' worth
    // or no other atom is present.
    if (rests <= 1 && !order.empty()) present.push_back(order[0] + 1);
    if (rests == 0 && !order.empty()) {
      const bool twice = arm_weights[order[0]] >= atoms.instance || order.size() < 2 ||
                         arm_weights[order[1]] < atoms.presence;
      present.push_back(twice ? order[0] + 1 : order[1] + 1);
    }
  } else {
    for (int k : order) {
      if (arm_weights[k] < atoms.presence || present.size() >= 2) break;
      present.push_back(k + 1);
      if (arm_weights[k] >= atoms.instance && present.size() < 2) present.push_back(k + 1);
    }
  }
  while (present.size() < 2) present.push_back(0);
  return Ordered(present[0], present[1]);
}

std::string PairName(const std::array<int, 2>& pair, const PostureAtoms& atoms) {
  return atoms.names[pair[0]] + "+" + atoms.names[pair[1]];
}

Posture DecomposePosture(const std::vector<float>& descriptor, const std::vector<float>& user_rest,
                         const PostureAtoms& atoms, std::optional<int> arms_at_rest) {
  if (descriptor.size() != atoms.rest.size()) {
    throw std::invalid_argument("the descriptor has " + std::to_string(descriptor.size()) + " bins, the atoms " +
                                std::to_string(atoms.rest.size()));
  }
  const std::vector<float>& a0 = user_rest.size() == descriptor.size() ? user_rest : atoms.rest;
  Posture p;
  double alpha0 = 0;
  const std::vector<float> residual = RestResidual(descriptor, a0, &alpha0);
  const std::vector<double> arm_weights =
      atoms.weights == AtomWeights::kMatchingPursuit
          ? MatchingPursuitWeights(residual, atoms.arms, atoms.iterations, atoms.overlap_threshold)
          : NonNegativeWeights(residual, atoms.arms);
  p.weights.push_back(alpha0);
  p.weights.insert(p.weights.end(), arm_weights.begin(), arm_weights.end());
  p.pair = alpha0 > 0 ? PairFromWeights(arm_weights, atoms, arms_at_rest) : std::array<int, 2>{0, 0};
  return p;
}

void UserRest::Update(const std::vector<float>& descriptor, bool both_arms_at_rest) {
  if (!both_arms_at_rest || descriptor.empty()) return;
  double norm = 0;
  for (float v : descriptor) norm += static_cast<double>(v) * v;
  norm = std::sqrt(norm);
  if (norm == 0) return;
  if (mean_.size() != descriptor.size()) mean_.assign(descriptor.size(), 0.0), seen_ = 0;
  ++seen_;
  // The plain mean for the first frames, then an exponential one.
  const double a = 1.0 / std::min(seen_, frames_);
  for (size_t i = 0; i < mean_.size(); ++i) mean_[i] += a * (descriptor[i] / norm - mean_[i]);
  double m = 0;
  for (double v : mean_) m += v * v;
  m = std::sqrt(m);
  unit_.resize(mean_.size());
  for (size_t i = 0; i < mean_.size(); ++i) unit_[i] = static_cast<float>(mean_[i] / m);
}

}  // namespace irbench
