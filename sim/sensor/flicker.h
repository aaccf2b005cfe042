#pragma once
// Illumination flicker over time: the screen's changing content (cuts, fades,
// flashes; seeded) and mains/PWM modulation of the illuminators integrated over
// the exposure. Level 1 is the clean render's lighting.

#include <cstdint>
#include <vector>

#include "sim/sensor/sensor_model.h"

namespace irbench {

class FlickerModel {
 public:
  // Precomputes the seeded screen events over [start_s, end_s].
  FlickerModel(const FlickerParams& params, uint64_t seed, double start_s, double end_s);

  // Mean illumination level over the exposure [t, t + exposure_s] of a
  // surface lit by the screen and the illuminators alike: ScreenMean x MainsMean.
  double Level(double t, double exposure_s) const;
  // The screens' content light over the exposure: the content level at its
  // middle plus the flashes' share.
  double ScreenMean(double t, double exposure_s) const;
  // The illuminators' mains/PWM modulation averaged over the exposure.
  double MainsMean(double t, double exposure_s) const;
  // The screen-content part alone at time t.
  double ScreenLevel(double t) const;

 private:
  struct Segment {
    double start = 0;
    double level = 1;
  };
  FlickerParams params_;
  std::vector<Segment> segments_;   // screen level changes (fade starts)
  std::vector<double> flashes_;     // flash start times
  double mains_phase_ = 0;
};

}  // namespace irbench
