#include "sim/sensor/flicker.h"

#include <algorithm>
#include <cmath>

namespace irbench {
FlickerModel::FlickerModel(const FlickerParams& params, uint64_t seed, double start_s, double end_s)
    : params_(params) {
  const uint64_t stream = MixHash(seed, 0xF11C4E5ull);
  uint64_t counter = 0;
  segments_.push_back({-1e9, 1.0});
  if (params.screen_amplitude > 0 && params.cut_rate_hz > 0) {
    // Cuts form a Poisson process; each sets a new level 1 + amplitude * N(0, 1).
    double t = start_s - 1.0;
    while (true) {
      t += -std::log(1.0 - UniformFromHash(stream, counter++)) / params.cut_rate_hz;
      if (t > end_s + 1.0) break;
      float z0, z1;
      StandardNormalPair(MixHash(stream, counter++), &z0, &z1);
      segments_.push_back({t, std::max(0.05, 1.0 + params.screen_amplitude * z0)});
    }
  }
  if (params.flash_rate_hz > 0) {
    double t = start_s - 1.0;
    while (true) {
      t += -std::log(1.0 - UniformFromHash(stream, counter++)) / params.flash_rate_hz;
      if (t > end_s + 1.0) break;
      flashes_.push_back(t);
    }
  }
  mains_phase_ = 2 * M_PI * UniformFromHash(stream, counter++);
}

double FlickerModel::ScreenLevel(double t) const {
  // The last change at or before t, faded in from the one before.
  auto it = std::upper_bound(segments_.begin(), segments_.end(), t,
                             [](double time, const Segment& s) { return time < s.start; });
  const Segment& current = *(it - 1);
  if (it - 1 == segments_.begin() || params_.fade_s <= 0) return current.level;
  const Segment& previous = *(it - 2);
  const double u = std::min(1.0, (t - current.start) / params_.fade_s);
  return previous.level + (current.level - previous.level) * u;
}

double FlickerModel::ScreenMean(double t, double exposure_s) const {
  double level = ScreenLevel(t + 0.5 * exposure_s);
  // Flashes: the fraction of the exposure each one overlaps.
  for (double start : flashes_) {
    const double overlap =
        std::min(t + exposure_s, start + params_.flash_s) - std::max(t, start);
    if (overlap > 0) level += params_.flash_gain * overlap / std::max(exposure_s, 1e-9);
  }
  return level;
}

double FlickerModel::MainsMean(double t, double exposure_s) const {
  if (params_.mains_depth <= 0 || params_.mains_hz <= 0) return 1.0;
  // Mean of 1 + d sin(w t + phi) over [t, t + e].
  const double w = 2 * M_PI * params_.mains_hz;
  const double mean_sin =
      exposure_s > 0
          ? (std::cos(w * t + mains_phase_) - std::cos(w * (t + exposure_s) + mains_phase_)) / (w * exposure_s)
          : std::sin(w * t + mains_phase_);
  return 1.0 + params_.mains_depth * mean_sin;
}

double FlickerModel::Level(double t, double exposure_s) const {
  return ScreenMean(t, exposure_s) * MainsMean(t, exposure_s);
}

}  // namespace irbench
