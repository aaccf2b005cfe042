#pragma once
// A voxelised stick figure for the NSS tests and benchmark: capsules for the
// torso, shoulders, neck and limbs and a sphere for the head, standing at the
// origin facing +y (its right is +x), with the true bones it was built on.

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <map>
#include <string>
#include <vector>

#include "tracker/hull/voxel_hull.h"

namespace irbench::testing {

struct StickFigure {
  // The true bone polylines by limb label (head: neck base to crown).
  std::map<std::string, std::vector<Eigen::Vector3d>> bones;
  VoxelHull hull;
};

// Arms: `right_elbow`, `right_wrist`, `left_elbow`, `left_wrist`.
inline StickFigure MakeStickFigure(const Eigen::Vector3d& right_elbow, const Eigen::Vector3d& right_wrist,
                                   const Eigen::Vector3d& left_elbow, const Eigen::Vector3d& left_wrist,
                                   double voxel_size_m = 0.02) {
  struct Capsule {
    Eigen::Vector3d a, b;
    double r;
  };
  const Eigen::Vector3d rs(0.2, 0, 1.4), ls(-0.2, 0, 1.4), rh(0.1, 0, 0.95), lh(-0.1, 0, 0.95);
  const Eigen::Vector3d rk(0.12, 0.02, 0.52), lk(-0.12, 0.02, 0.52), ra(0.13, 0, 0.08), la(-0.13, 0, 0.08);
  const std::vector<Capsule> capsules = {
      {{0, 0, 0.95}, {0, 0, 1.38}, 0.12},  // torso
      {ls, rs, 0.06},                      // shoulders
      {lh, rh, 0.08},                      // pelvis
      {{0, 0, 1.4}, {0, 0, 1.55}, 0.05},   // neck
      {{0, 0, 1.65}, {0, 0, 1.65}, 0.10},  // head
      {rs, right_elbow, 0.045}, {right_elbow, right_wrist, 0.04},
      {ls, left_elbow, 0.045},  {left_elbow, left_wrist, 0.04},
      {rh, rk, 0.065},          {rk, ra, 0.05},
      {lh, lk, 0.065},          {lk, la, 0.05},
  };
  StickFigure f;
  f.bones = {{"right_arm", {rs, right_elbow, right_wrist}}, {"left_arm", {ls, left_elbow, left_wrist}},
             {"right_leg", {rh, rk, ra}},                   {"left_leg", {lh, lk, la}},
             {"head", {{0, 0, 1.4}, {0, 0, 1.75}}}};
  VoxelHull& h = f.hull;
  h.voxel_size_m = voxel_size_m;
  h.origin_m = Eigen::Vector3d(-1.0, -1.0, 0.0);
  h.nx = h.ny = static_cast<int>(std::lround(2.0 / voxel_size_m));
  h.nz = static_cast<int>(std::lround(2.4 / voxel_size_m));
  h.occupied.assign(size_t(h.nx) * h.ny * h.nz, 0);
  for (int z = 0; z < h.nz; ++z) {
    for (int y = 0; y < h.ny; ++y) {
      for (int x = 0; x < h.nx; ++x) {
        const Eigen::Vector3d p = h.VoxelCenter(x, y, z);
        for (const Capsule& c : capsules) {
          const Eigen::Vector3d ab = c.b - c.a;
          const double t = ab.squaredNorm() > 0 ? std::clamp((p - c.a).dot(ab) / ab.squaredNorm(), 0.0, 1.0) : 0.0;
          if ((p - (c.a + t * ab)).norm() <= c.r) {
            h.occupied[h.Index(x, y, z)] = 1;
            ++h.occupied_count;
            break;
          }
        }
      }
    }
  }
  return f;
}

// Distance from `p` to a polyline.
inline double DistanceToPolyline(const Eigen::Vector3d& p, const std::vector<Eigen::Vector3d>& line) {
  double best = (p - line[0]).norm();
  for (size_t i = 1; i < line.size(); ++i) {
    const Eigen::Vector3d ab = line[i] - line[i - 1];
    const double t = std::clamp((p - line[i - 1]).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
    best = std::min(best, (p - (line[i - 1] + t * ab)).norm());
  }
  return best;
}

}  // namespace irbench::testing
