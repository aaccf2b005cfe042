#pragma once
// Thesis 6.5: the pointing ray runs from the head centre (the eyes' proxy)
// through the hand tip; where it meets a screen gives screen coordinates and
// the nearest named target.

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "geometry/screen.h"
#include "tracker/hull/voxel_hull.h"

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

// The head centre measured on the voxel hull, the pointing ray's origin. The
// model's head rides on the trunk, which the arms pull about: while a user
// pointed, the tracked head sat 1-2 cm to the body's left of the truth's and,
// pointing upwards, 3 cm low — 2-3 deg of pointing error on a ray 0.6 m
// long. The hull's head is where the silhouettes put it, whatever the trunk.
struct HullHeadOptions {
  // Voxels within this horizontal distance of the model's head centre are
  // the head's; their top is the head's top.
  double radius_m = 0.12;
  // The centre's x and y: the centroid of those voxels within this much of
  // the height below the top (above the chin and the shoulders).
  double slab = 0.08;
  // The centre's height: this much of the height below the top's upper face.
  // The sim's five persons have their head joints 0.067-0.084 of their
  // heights below the crown.
  double below_top = 0.075;
  // Moved this far back, against the facing direction: the face and nose
  // put the slab's centroid ahead of the skull's centre.
  double back_m = 0.01;
  // nullopt (keep the model's head) when the top lies further than this from
  // the model's crown (the model's head centre plus below_top of the height):
  // a hand over the head, or a head the hull lost.
  double max_gap_m = 0.08;
  void Check() const;  // throws InputError naming the field
};

// `model_head`: the model's head centre; `forward`: the direction the upper
// body faces (world, need not be unit; only x and y are used); `height_m`:
// the user's height.
std::optional<Eigen::Vector3d> HullHeadCentre(const VoxelHull& hull, const Eigen::Vector3d& model_head,
                                              const Eigen::Vector3d& forward, double height_m,
                                              const HullHeadOptions& options = {});

}  // namespace irbench
