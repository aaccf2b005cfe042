#pragma once
// The parametric body generator: a watertight skinned human from a few
// measures. The body is the smooth union of anatomical primitives (a lofted
// torso with chest, belly and buttocks, neck, skull and jaw, deltoids, tapered
// limbs with calf and forearm bulges, hands with a thumb, feet), clothing as an
// offset of the clothed parts, polygonised by marching tetrahedra (closed and
// manifold by construction) and skinned with weights that blend smoothly across
// every joint. Rules and figures in docs/avatars.md.

#include <string>

#include "sim/body/avatar.h"

namespace irbench {

struct BodyShape {
  double shoulder_width = 1.0;  // ratios to the average body of that height
  double hip_width = 1.0;
  double arm_length = 1.0;
  double leg_length = 1.0;
  double head_size = 1.0;
  double belly = 0.0;           // 0..1: extra abdominal girth
  std::string clothing = "tight";  // tight, loose_shirt, jacket
  double cell_m = 0;            // polygonisation cell; 0: height / 115
};

// Builds the avatar of `params` (height, build, albedos) with `shape`.
Avatar BuildParametricAvatar(const AvatarParams& params, const BodyShape& shape);

}  // namespace irbench
