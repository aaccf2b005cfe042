#include "tracker/pose/arm_points.h"

#include <algorithm>

namespace irbench {

using Eigen::Vector3d;

ArmChains ChainArmPoints(const std::vector<AxisPoint3d>& axis3d, double link_m) {
  ArmChains out;
  for (const AxisPoint3d& a : axis3d) {
    if (a.part == BodyPart::kArm) out.points.push_back(a.p_in_world);
  }
  const int n = static_cast<int>(out.points.size());
  out.chain.assign(n, -1);
  for (int seed = 0; seed < n; ++seed) {
    if (out.chain[seed] >= 0) continue;
    std::vector<int> stack = {seed};
    out.chain[seed] = out.count;
    while (!stack.empty()) {
      const int i = stack.back();
      stack.pop_back();
      for (int j = 0; j < n; ++j) {
        if (out.chain[j] < 0 && (out.points[i] - out.points[j]).norm() < link_m) {
          out.chain[j] = out.count;
          stack.push_back(j);
        }
      }
    }
    ++out.count;
  }
  return out;
}

std::array<std::vector<Vector3d>, 2> ArmPointsBySide(const std::vector<Vector3d>& points,
                                                     const std::vector<int>& chain,
                                                     int chains,
                                                     const Vector3d& right_shoulder,
                                                     const Vector3d& left_shoulder) {
  const int n = static_cast<int>(points.size());
  std::array<std::vector<Vector3d>, 2> out;
  for (int c = 0; c < chains; ++c) {
    double best_right = 1e9, best_left = 1e9;
    for (int i = 0; i < n; ++i) {
      if (chain[i] != c) continue;
      best_right = std::min(best_right, (points[i] - right_shoulder).norm());
      best_left = std::min(best_left, (points[i] - left_shoulder).norm());
    }
    const int side = best_right <= best_left ? 0 : 1;
    for (int i = 0; i < n; ++i) {
      if (chain[i] == c) out[side].push_back(points[i]);
    }
  }
  return out;
}

std::optional<Vector3d> FarthestArmPoint(const std::vector<Vector3d>& points,
                                         const Vector3d& shoulder) {
  std::optional<Vector3d> farthest;
  double farthest_d = kArmApartM;
  for (const Vector3d& p : points) {
    const double d = (p - shoulder).norm();
    if (d > farthest_d) {
      farthest_d = d;
      farthest = p;
    }
  }
  return farthest;
}

}  // namespace irbench
