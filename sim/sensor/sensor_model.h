#pragma once
// The camera sensor after the EMVA 1288 linear model: photons -> electrons
// (quantum efficiency, PRNU) + dark signal (dark current x exposure, DSNU) with
// photon shot noise and dark (read) noise -> full-well clipping -> system gain
// and black level -> ADC quantisation; then an optional washed-out tone curve
// to 8 bits. Everything random is drawn from counter-based hashes of (seed,
// camera, frame, pixel), so renders are reproducible and frames independent.

#include <cstdint>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <string>

#include "sim/sensor/optics.h"

namespace irbench {

struct SensorParams {
  // Photons reaching a pixel per millisecond of exposure when the rendered
  // radiance is 1 (the brightest the clean render can show).
  double photons_per_ms = 2000.0;
  double quantum_efficiency = 0.35;   // eta at 850 nm
  double quantum_efficiency_940 = 0.20;  // eta at 940 nm (silicon sees less of it)
  double full_well_e = 6000.0;        // saturation capacity, electrons
  double system_gain_dn_per_e = 0.04; // K, DN per electron
  double dark_noise_e = 10.0;         // sigma_d, temporal dark (read) noise, electrons
  double dark_current_e_per_s = 40.0; // mu_I
  double dsnu_e = 6.0;                // spatial std of the dark signal, electrons
  double prnu = 0.015;                // spatial std of the relative gain
  int bit_depth = 8;                  // ADC, 8..16
  double black_level_dn = 10.0;       // offset added before quantisation
  // Tone curve to the 8-bit output: out = 255 * (lift + (1 - lift - ceiling_drop) * x^gamma),
  // x = DN / (2^bits - 1). lift 0, ceiling_drop 0, gamma 1: linear (raw DN).
  double tone_lift = 0.0;
  double tone_ceiling_drop = 0.0;
  double tone_gamma = 1.0;
  bool noise = true;  // false: the mean signal only (for tests and clean renders)

  // Throws InputError naming `file` and `field_prefix` + the knob.
  void Check(const std::string& file, const std::string& field_prefix) const;
  bool LinearTone() const { return tone_lift == 0 && tone_ceiling_drop == 0 && tone_gamma == 1; }
  nlohmann::json ToJson() const;
};

struct FlickerParams {
  // Screen content: the light the screen throws changes at cuts (a Poisson
  // process), by fades and by flashes; its relative level has this std.
  double screen_amplitude = 0.0;   // relative std of the screen-driven level
  double cut_rate_hz = 0.5;        // mean scene cuts per second
  double fade_s = 0.4;             // each change is a linear fade of this length
  double flash_rate_hz = 0.0;      // short bright flashes per second
  double flash_gain = 0.5;         // a flash adds this much relative light
  double flash_s = 0.1;
  // Mains or PWM modulation of the illuminators: level 1 + depth*sin(2 pi f t),
  // integrated over each exposure, so it beats against the frame rate.
  double mains_hz = 100.0;
  double mains_depth = 0.0;

  void Check(const std::string& file, const std::string& field_prefix) const;
  nlohmann::json ToJson() const;
};

// Capture faults, recorded in the truth.
struct CaptureParams {
  double drop_rate = 0.0;      // probability that a camera drops a frame (it repeats the last one)
  double sync_jitter_ms = 0.0; // std of a camera's capture instant around the frame time
  // Rolling shutter: the time from the first row's exposure start to the
  // last's; each row sees its own flicker (banding). 0: global shutter.
  double rolling_shutter_ms = 0.0;
};

struct SensorSetup {
  std::string preset = "clean";
  // Whether the preset models a sensor at all: false for `clean`, whose
  // frames are the renderer's grey (no noise, flicker, optics, soft shadows
  // by default).
  bool models_sensor = false;
  SensorParams sensor;
  FlickerParams flicker;
  OpticsParams optics;
  CaptureParams capture;
};

nlohmann::json OpticsToJson(const OpticsParams& optics);
nlohmann::json CaptureToJson(const CaptureParams& capture);
// Every knob of a camera's sensor setup, as calib/cameras.json lists it per
// camera: {preset, emva1288, flicker, optics, capture}.
nlohmann::json SensorSetupJson(const SensorSetup& setup);

// "clean" (no noise, no flicker, linear), "thesis" (the thesis's 1.2: dark,
// flickering, washed out, grainy), "harsh". nullopt for unknown names.
std::optional<SensorSetup> SensorPreset(const std::string& name);
// Overrides knobs from a JSON object ({"sensor": {...}, "flicker": {...}});
// unknown knobs and bad values throw InputError naming file and field.
void ApplySensorOverrides(const nlohmann::json& overrides,
                          const std::string& file,
                          const std::string& field_prefix,
                          SensorSetup* setup);

class SensorModel {
 public:
  // Fixed patterns (DSNU, PRNU) are drawn once per camera from (seed, camera).
  SensorModel(const SensorParams& params, uint64_t seed, const std::string& camera, int width, int height);

  // `radiance`: CV_32FC1 relative radiance (1 = the clean render's white),
  // already multiplied by the frame's illumination level. Returns the raw
  // DN image (CV_16UC1, linear, before the tone curve).
  cv::Mat Expose(const cv::Mat& radiance, double exposure_ms, uint64_t frame_index) const;
  // Raw DN to the 8-bit output through the tone curve (or, linear with more than
  // 8 bits, the raw DN kept in 16 bits).
  cv::Mat ToOutput(const cv::Mat& raw_dn) const;

  const SensorParams& params() const { return params_; }
  const cv::Mat& prnu_pattern() const { return prnu_; }   // CV_32F, relative gain - 1
  const cv::Mat& dsnu_pattern() const { return dsnu_; }   // CV_32F, electrons

 private:
  SensorParams params_;
  uint64_t stream_;  // (seed, camera) mixed
  cv::Mat prnu_, dsnu_;
  cv::Mat tone_lut_;  // CV_8U, 2^bits entries, when the output is 8-bit
};

// Counter-based randomness: a 64-bit hash, and two independent standard
// normals from one counter (Box–Muller).
uint64_t MixHash(uint64_t a, uint64_t b);
// A uniform number in [0, 1) from MixHash(stream, counter).
double UniformFromHash(uint64_t stream, uint64_t counter);
void StandardNormalPair(uint64_t counter, float* z0, float* z1);

}  // namespace irbench
