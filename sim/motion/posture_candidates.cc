#include "sim/motion/posture_candidates.h"

namespace irbench {

const std::vector<CandidateArm>& PostureCandidateArms() {
  const Eigen::Vector3d none = Eigen::Vector3d::Zero(), up(0, 0, 1), fwd(0, 1, 0), in(-1, 0, 0);
  static const std::vector<CandidateArm> arms = {
      {"straight, out to the side, 45 deg down", 0, -45, 0, none},
      {"straight, out to the side, 20 deg down", 0, -20, 0, none},
      {"straight, out to the side, horizontal", 0, 0, 0, none},
      {"straight, out to the side, 20 deg up", 0, 20, 0, none},
      {"straight, out to the side, 45 deg up", 0, 45, 0, none},
      {"straight, out to the side, 70 deg up", 0, 70, 0, none},
      {"straight, diagonally forward, 45 deg down", 45, -45, 0, none},
      {"straight, diagonally forward, 20 deg down", 45, -20, 0, none},
      {"straight, diagonally forward, horizontal", 45, 0, 0, none},
      {"straight, diagonally forward, 20 deg up", 45, 20, 0, none},
      {"straight, diagonally forward, 45 deg up", 45, 45, 0, none},
      {"straight, diagonally forward, 70 deg up", 45, 70, 0, none},
      {"straight, forward, 45 deg down", 90, -45, 0, none},
      {"straight, forward, 20 deg down", 90, -20, 0, none},
      {"straight, forward, horizontal", 90, 0, 0, none},
      {"straight, forward, 20 deg up", 90, 20, 0, none},
      {"straight, forward, 45 deg up", 90, 45, 0, none},
      {"straight, forward, 70 deg up", 90, 70, 0, none},
      {"overhead (the A2 atom)", 10, 80, 5, none},
      {"straight, behind the shoulder line, 45 deg up", -30, 45, 0, none},
      {"straight, behind the shoulder line, horizontal", -30, 0, 0, none},
      {"straight, behind the shoulder line, 45 deg down", -30, -45, 0, none},
      {"upper arm out horizontal, forearm up", 0, 0, 90, up},
      {"upper arm out horizontal, forearm forward", 0, 0, 90, fwd},
      {"upper arm forward horizontal, forearm up", 90, 0, 90, up},
      {"upper arm forward horizontal, forearm across", 90, 0, 80, in},
      {"upper arm hanging, forearm forward", 0, -75, 90, fwd},
      {"upper arm 45 deg down diagonally forward, forearm across the belly", 45, -45, 100, in},
      {"upper arm out 45 deg up, forearm over the head", 0, 45, 110, in},
      {"straight, across the chest", 120, 0, 0, none},
  };
  return arms;
}

std::vector<std::string> PostureCandidateDescriptions() {
  std::vector<std::string> out;
  for (const CandidateArm& a : PostureCandidateArms()) out.push_back(a.about);
  return out;
}

}  // namespace irbench
