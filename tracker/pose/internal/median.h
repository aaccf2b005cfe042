#pragma once
// Private to tracker/pose: the median the pose tracker and its body
// calibration take of per-frame measurements.

#include <algorithm>
#include <vector>

namespace irbench::pose_internal {

// The upper median of `v` (the element at size / 2 once sorted); `v` must
// not be empty.
inline double Median(std::vector<double> v) {
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

}  // namespace irbench::pose_internal
