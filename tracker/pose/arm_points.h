#pragma once
// The 3D arm axis points (thesis 4.4.2) as the pose tracker reads them: split
// into chains, one per seen arm, and each chain given to a shoulder. The arm
// direction proposal (thesis 6.3.2, particle_filter.h) and the rest state
// (6.4) read them. World frame, metres.

#include <Eigen/Core>
#include <array>
#include <optional>
#include <vector>

#include "tracker/frontend/frontend.h"

namespace irbench {

// This frame's 3D arm axis points (world, metres) and the chain each belongs to.
struct ArmChains {
  std::vector<Eigen::Vector3d> points;
  std::vector<int> chain;  // per point
  int count = 0;
};

// The 3D arm axis points (BodyPart::kArm) of `axis3d` split into chains
// (single linkage within `link_m` metres), one per seen arm; once per frame.
ArmChains ChainArmPoints(const std::vector<AxisPoint3d>& axis3d, double link_m = 0.08);

// The chains' points by side (right, left): each chain belongs to the
// shoulder (world, metres) nearest its nearest point, so an arm reaching
// across the body stays with the shoulder it starts from.
std::array<std::vector<Eigen::Vector3d>, 2> ArmPointsBySide(
    const std::vector<Eigen::Vector3d>& points,
    const std::vector<int>& chain,
    int chains,
    const Eigen::Vector3d& right_shoulder,
    const Eigen::Vector3d& left_shoulder);

// Arm axis points farther than this (metres) from the shoulder show the arm
// apart from the body.
constexpr double kArmApartM = 0.15;

// The arm point farthest from the shoulder (world, metres), if one lies
// beyond kArmApartM.
std::optional<Eigen::Vector3d> FarthestArmPoint(const std::vector<Eigen::Vector3d>& points,
                                                const Eigen::Vector3d& shoulder);

}  // namespace irbench
