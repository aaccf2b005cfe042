#pragma once
// Thesis 6.5: the pointing ray runs from the head centre (the eyes' proxy)
// through the hand tip; where it meets a screen gives screen coordinates and
// the nearest named target.

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "sim/scene/screen.h"

namespace irbench {

struct PointingRay {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();  // head centre, world metres
  Eigen::Vector3d dir = Eigen::Vector3d::UnitY();    // unit
  std::optional<std::string> screen;                 // the screen it hits first
  std::optional<Eigen::Vector2d> screen_hit;         // metres along that screen
  std::optional<std::string> target;                 // nearest named target there
};

// nullopt when head and hand tip coincide.
std::optional<PointingRay> Pointing(const Eigen::Vector3d& head, const Eigen::Vector3d& hand_tip,
                                    const std::vector<ScreenSurface>& screens);

}  // namespace irbench
