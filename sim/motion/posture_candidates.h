#pragma once
// The thesis's 30 candidate postures for selecting the posture atoms
// (5.1.2), played one after the other by the library motion
// `posture_candidates` (docs/motion.md): one arm held in each, the other at
// rest. Straight arms over a grid of directions (azimuth 0 out to the side,
// 45 diagonally forward, 90 forward, -30 behind the shoulder line;
// elevation -45 to 70 deg), the overhead atom, and eight bent arms. The atoms
// A1, A3 and A4 are candidates C03, C05 and C01, A2 is C19.

#include <Eigen/Core>
#include <string>
#include <vector>

namespace irbench {

struct CandidateArm {
  const char* about;     // a description of the arm
  double az, el, elbow;  // degrees: the upper arm's azimuth and elevation, the elbow's flexion
  Eigen::Vector3d bend;  // the forearm's bending direction (chest frame), zero for the default
};

// The candidates in order: candidate Cnn is element nn - 1.
const std::vector<CandidateArm>& PostureCandidateArms();

// Their descriptions, in the same order.
std::vector<std::string> PostureCandidateDescriptions();

}  // namespace irbench
