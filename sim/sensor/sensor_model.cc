#include "sim/sensor/sensor_model.h"

#include <cmath>
#include <type_traits>

#include "common/atomic_file.h"
#include "common/error.h"

namespace irbench {

uint64_t MixHash(uint64_t a, uint64_t b) {
  // SplitMix64 finaliser over a combination of the two words.
  uint64_t z = a * 0x9E3779B97F4A7C15ull + b + 0x632BE59BD9B4E019ull;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

double UniformFromHash(uint64_t stream, uint64_t counter) {
  return double(MixHash(stream, counter) >> 11) / 9007199254740992.0;  // 53 bits / 2^53
}

void StandardNormalPair(uint64_t counter, float* z0, float* z1) {
  const uint64_t bits = MixHash(counter, 0xD1B54A32D192ED03ull);
  // Two 32-bit uniforms in (0, 1].
  const double u1 = (double(bits >> 32) + 1.0) / 4294967296.0;
  const double u2 = double(bits & 0xFFFFFFFFull) / 4294967296.0;
  const double r = std::sqrt(-2.0 * std::log(u1));
  const double phi = 2.0 * M_PI * u2;
  *z0 = static_cast<float>(r * std::cos(phi));
  *z1 = static_cast<float>(r * std::sin(phi));
}

namespace {

void CheckRange(double value, double lo, double hi, const std::string& file, const std::string& field) {
  if (!(value >= lo && value <= hi)) {
    throw InputError(file, field,
                     "must be in [" + std::to_string(lo) + ", " + std::to_string(hi) + "] (got " +
                         std::to_string(value) + ")");
  }
}

// Every knob of a group, once: its name and member. Writing JSON, applying a
// rig's overrides and naming bad fields all go through these tables.
template <class F>
void VisitKnobs(SensorParams& p, F&& f) {
  f("photons_per_ms", p.photons_per_ms);
  f("quantum_efficiency", p.quantum_efficiency);
  f("quantum_efficiency_940", p.quantum_efficiency_940);
  f("full_well_e", p.full_well_e);
  f("system_gain_dn_per_e", p.system_gain_dn_per_e);
  f("dark_noise_e", p.dark_noise_e);
  f("dark_current_e_per_s", p.dark_current_e_per_s);
  f("dsnu_e", p.dsnu_e);
  f("prnu", p.prnu);
  f("bit_depth", p.bit_depth);
  f("black_level_dn", p.black_level_dn);
  f("tone_lift", p.tone_lift);
  f("tone_ceiling_drop", p.tone_ceiling_drop);
  f("tone_gamma", p.tone_gamma);
  f("noise", p.noise);
}

template <class F>
void VisitKnobs(FlickerParams& p, F&& f) {
  f("screen_amplitude", p.screen_amplitude);
  f("cut_rate_hz", p.cut_rate_hz);
  f("fade_s", p.fade_s);
  f("flash_rate_hz", p.flash_rate_hz);
  f("flash_gain", p.flash_gain);
  f("flash_s", p.flash_s);
  f("mains_hz", p.mains_hz);
  f("mains_depth", p.mains_depth);
}

template <class F>
void VisitKnobs(OpticsParams& p, F&& f) {
  f("f_number", p.f_number);
  f("focal_length_mm", p.focal_length_mm);
  f("focus_distance_m", p.focus_distance_m);
  f("vignetting", p.vignetting);
  f("glare_gain", p.glare_gain);
  f("glare_threshold", p.glare_threshold);
  f("glare_sigma_px", p.glare_sigma_px);
  f("motion_blur_samples", p.motion_blur_samples);
}

template <class F>
void VisitKnobs(CaptureParams& p, F&& f) {
  f("drop_rate", p.drop_rate);
  f("sync_jitter_ms", p.sync_jitter_ms);
  f("rolling_shutter_ms", p.rolling_shutter_ms);
}

template <class P>
nlohmann::json KnobsToJson(const P& params) {
  nlohmann::json j = nlohmann::json::object();
  P copy = params;
  VisitKnobs(copy, [&](const char* name, const auto& value) { j[name] = value; });
  return j;
}

// Sets the knobs named in `knobs`; unknown names and wrong types throw.
template <class P>
void ApplyKnobs(const nlohmann::json& knobs, const std::string& file, const std::string& field, P* params) {
  if (!knobs.is_object()) throw InputError(file, field, "expected an object");
  for (const auto& [key, value] : knobs.items()) {
    bool known = false;
    VisitKnobs(*params, [&, &key = key, &value = value](const char* name, auto& member) {
      if (key != name) return;
      known = true;
      using T = std::decay_t<decltype(member)>;
      const bool ok = std::is_same_v<T, bool>  ? value.is_boolean()
                      : std::is_same_v<T, int> ? value.is_number_integer()
                                               : value.is_number();
      if (!ok) throw InputError(file, field + "." + key, "wrong type: " + value.dump());
      // An integer beyond int would wrap into range (4294967304 -> 8).
      if constexpr (std::is_same_v<T, int>) {
        if (std::abs(value.template get<double>()) > 1e9) {
          throw InputError(file, field + "." + key, "out of range: " + value.dump());
        }
      }
      member = value.template get<T>();
    });
    if (!known) throw InputError(file, field + "." + key, "unknown knob");
  }
}

void CheckOptics(const OpticsParams& o, const std::string& file, const std::string& p) {
  CheckRange(o.f_number, 0, 64, file, p + "f_number");
  CheckRange(o.focal_length_mm, 0.5, 500, file, p + "focal_length_mm");
  CheckRange(o.focus_distance_m, 0.1, 1000, file, p + "focus_distance_m");
  CheckRange(o.vignetting, 0, 1, file, p + "vignetting");
  CheckRange(o.glare_gain, 0, 10, file, p + "glare_gain");
  CheckRange(o.glare_threshold, 0, 10, file, p + "glare_threshold");
  CheckRange(o.glare_sigma_px, 0.5, 100, file, p + "glare_sigma_px");
  CheckRange(o.motion_blur_samples, 1, 16, file, p + "motion_blur_samples");
}

void CheckCapture(const CaptureParams& c, const std::string& file, const std::string& p) {
  CheckRange(c.drop_rate, 0, 0.5, file, p + "drop_rate");
  CheckRange(c.sync_jitter_ms, 0, 100, file, p + "sync_jitter_ms");
  CheckRange(c.rolling_shutter_ms, 0, 1000, file, p + "rolling_shutter_ms");
}

}  // namespace

void SensorParams::Check(const std::string& file, const std::string& p) const {
  CheckRange(photons_per_ms, 0, 1e9, file, p + "photons_per_ms");
  CheckRange(quantum_efficiency, 0, 1, file, p + "quantum_efficiency");
  CheckRange(quantum_efficiency_940, 0, 1, file, p + "quantum_efficiency_940");
  CheckRange(full_well_e, 1, 1e7, file, p + "full_well_e");
  CheckRange(system_gain_dn_per_e, 1e-6, 1e3, file, p + "system_gain_dn_per_e");
  CheckRange(dark_noise_e, 0, 1e4, file, p + "dark_noise_e");
  CheckRange(dark_current_e_per_s, 0, 1e7, file, p + "dark_current_e_per_s");
  CheckRange(dsnu_e, 0, 1e4, file, p + "dsnu_e");
  CheckRange(prnu, 0, 0.5, file, p + "prnu");
  CheckRange(bit_depth, 8, 16, file, p + "bit_depth");
  CheckRange(black_level_dn, 0, (1 << bit_depth) - 1, file, p + "black_level_dn");
  CheckRange(tone_lift, 0, 0.9, file, p + "tone_lift");
  CheckRange(tone_ceiling_drop, 0, 0.9 - tone_lift, file, p + "tone_ceiling_drop");
  CheckRange(tone_gamma, 0.1, 10, file, p + "tone_gamma");
}

nlohmann::json SensorParams::ToJson() const { return KnobsToJson(*this); }

void FlickerParams::Check(const std::string& file, const std::string& p) const {
  CheckRange(screen_amplitude, 0, 1, file, p + "screen_amplitude");
  CheckRange(cut_rate_hz, 0, 100, file, p + "cut_rate_hz");
  CheckRange(fade_s, 0, 10, file, p + "fade_s");
  CheckRange(flash_rate_hz, 0, 100, file, p + "flash_rate_hz");
  CheckRange(flash_gain, 0, 10, file, p + "flash_gain");
  CheckRange(flash_s, 0, 10, file, p + "flash_s");
  CheckRange(mains_hz, 0, 100000, file, p + "mains_hz");
  CheckRange(mains_depth, 0, 1, file, p + "mains_depth");
}

nlohmann::json FlickerParams::ToJson() const { return KnobsToJson(*this); }

nlohmann::json OpticsToJson(const OpticsParams& optics) { return KnobsToJson(optics); }
nlohmann::json CaptureToJson(const CaptureParams& capture) { return KnobsToJson(capture); }

nlohmann::json SensorSetupJson(const SensorSetup& setup) {
  return {{"preset", setup.preset},
          {"emva1288", setup.sensor.ToJson()},
          {"flicker", setup.flicker.ToJson()},
          {"optics", OpticsToJson(setup.optics)},
          {"capture", CaptureToJson(setup.capture)}};
}

std::optional<SensorSetup> SensorPreset(const std::string& name) {
  SensorSetup s;
  s.preset = name;
  if (name == "clean") {
    s.sensor.noise = false;
    s.sensor.dark_current_e_per_s = 0;
    s.sensor.dsnu_e = 0;
    s.sensor.prnu = 0;
    s.sensor.black_level_dn = 0;
    // Radiance 1 at 10 ms exposure fills the 8-bit range exactly.
    s.sensor.quantum_efficiency = 1.0;
    s.sensor.quantum_efficiency_940 = 1.0;
    s.sensor.photons_per_ms = 255.0 / (0.04 * 10.0);
    s.sensor.full_well_e = 1e7;
    return s;
  }
  s.models_sensor = true;
  if (name == "thesis") {
    // Thesis 1.2: very dark, illumination that changes with the screen's
    // content, washed out with a limited grey range, grainy.
    s.sensor = SensorParams{};
    s.sensor.tone_lift = 0.12;
    s.sensor.tone_ceiling_drop = 0.35;
    s.sensor.tone_gamma = 0.8;
    s.flicker.screen_amplitude = 0.08;
    s.flicker.cut_rate_hz = 0.5;
    s.flicker.flash_rate_hz = 0.1;
    s.flicker.mains_depth = 0.05;
    // Thesis Fig. 1.3: "the image is blurry": a wide aperture in the dark.
    s.optics.f_number = 1.4;
    s.optics.focus_distance_m = 3.8;
    s.optics.vignetting = 0.5;
    s.optics.glare_gain = 0.3;
    // At 8 ms a hand at 2 m/s moves about one pixel: no sub-frames needed.
    s.optics.motion_blur_samples = 1;
    return s;
  }
  if (name == "harsh") {
    s.sensor = SensorParams{};
    s.sensor.photons_per_ms = 1000.0;
    s.sensor.dark_noise_e = 20.0;
    s.sensor.dark_current_e_per_s = 150.0;
    s.sensor.dsnu_e = 15.0;
    s.sensor.prnu = 0.03;
    s.sensor.tone_lift = 0.2;
    s.sensor.tone_ceiling_drop = 0.4;
    s.sensor.tone_gamma = 0.7;
    s.flicker.screen_amplitude = 0.2;
    s.flicker.cut_rate_hz = 1.5;
    s.flicker.flash_rate_hz = 0.4;
    s.flicker.mains_depth = 0.15;
    s.optics.f_number = 1.0;
    s.optics.focus_distance_m = 3.0;
    s.optics.vignetting = 0.8;
    s.optics.glare_gain = 0.6;
    s.optics.motion_blur_samples = 4;
    s.capture.drop_rate = 0.01;
    s.capture.sync_jitter_ms = 2.0;
    return s;
  }
  return std::nullopt;
}

void ApplySensorOverrides(const nlohmann::json& overrides,
                          const std::string& file,
                          const std::string& prefix,
                          SensorSetup* setup) {
  if (!overrides.is_object()) throw InputError(file, prefix, "expected an object");
  for (const auto& [group, knobs] : overrides.items()) {
    const std::string field = prefix + "." + group;
    if (group == "sensor") {
      ApplyKnobs(knobs, file, field, &setup->sensor);
      setup->sensor.Check(file, field + ".");
    } else if (group == "flicker") {
      ApplyKnobs(knobs, file, field, &setup->flicker);
      setup->flicker.Check(file, field + ".");
    } else if (group == "optics") {
      ApplyKnobs(knobs, file, field, &setup->optics);
      CheckOptics(setup->optics, file, field + ".");
    } else if (group == "capture") {
      ApplyKnobs(knobs, file, field, &setup->capture);
      CheckCapture(setup->capture, file, field + ".");
    } else {
      throw InputError(file, field, "unknown group (sensor, flicker, optics, capture)");
    }
  }
}

SensorModel::SensorModel(const SensorParams& params,
                         uint64_t seed,
                         const std::string& camera,
                         int width,
                         int height)
    : params_(params), stream_(MixHash(seed, Fnv1a64(camera))) {
  prnu_.create(height, width, CV_32FC1);
  dsnu_.create(height, width, CV_32FC1);
  const uint64_t pattern_stream = MixHash(stream_, 0x5EED);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      float a, b;
      StandardNormalPair(MixHash(pattern_stream, uint64_t(y) * width + x), &a, &b);
      prnu_.at<float>(y, x) = static_cast<float>(params.prnu * a);
      dsnu_.at<float>(y, x) = static_cast<float>(params.dsnu_e * b);
    }
  }
  if (params.bit_depth == 8 || !params.LinearTone()) {
    const int levels = 1 << params.bit_depth;
    tone_lut_.create(1, levels, CV_8UC1);
    for (int dn = 0; dn < levels; ++dn) {
      const double x = double(dn) / (levels - 1);
      const double y = params.tone_lift +
                       (1 - params.tone_lift - params.tone_ceiling_drop) * std::pow(x, params.tone_gamma);
      tone_lut_.at<uint8_t>(0, dn) = cv::saturate_cast<uint8_t>(std::lround(255.0 * y));
    }
  }
}

cv::Mat SensorModel::Expose(const cv::Mat& radiance, double exposure_ms, uint64_t frame_index) const {
  CV_Assert(radiance.type() == CV_32FC1 && radiance.size() == prnu_.size());
  const SensorParams& p = params_;
  const double photons_scale = p.photons_per_ms * exposure_ms;
  const float signal_scale = static_cast<float>(p.quantum_efficiency * photons_scale);
  const float dark_mean = static_cast<float>(p.dark_current_e_per_s * exposure_ms / 1000.0);
  const float read_sigma = static_cast<float>(p.dark_noise_e);
  const float gain = static_cast<float>(p.system_gain_dn_per_e);
  const float black = static_cast<float>(p.black_level_dn);
  const float full_well = static_cast<float>(p.full_well_e);
  const float max_dn = static_cast<float>((1 << p.bit_depth) - 1);
  const uint64_t frame_stream = MixHash(stream_, frame_index + 1);
  cv::Mat dn(radiance.size(), CV_16UC1);
  cv::parallel_for_(cv::Range(0, radiance.rows), [&](const cv::Range& rows) {
    for (int y = rows.start; y < rows.end; ++y) {
      const float* in = radiance.ptr<float>(y);
      const float* prnu = prnu_.ptr<float>(y);
      const float* dsnu = dsnu_.ptr<float>(y);
      uint16_t* out = dn.ptr<uint16_t>(y);
      for (int x = 0; x < radiance.cols; ++x) {
        // Collected charge: signal (with the pixel's gain) and dark current,
        // with their shot noise (Poisson variance = mean, drawn as a
        // Gaussian), clipped at the full well.
        const float signal_e = std::max(0.0f, in[x]) * signal_scale * (1.0f + prnu[x]);
        float charge = signal_e + dark_mean;
        float read = 0.0f;
        if (p.noise) {
          float z0, z1;
          StandardNormalPair(MixHash(frame_stream, uint64_t(y) * radiance.cols + x), &z0, &z1);
          charge += std::sqrt(charge) * z0;
          read = read_sigma * z1;
        }
        charge = std::min(std::max(charge, 0.0f), full_well);
        // Offsets that are not charge (DSNU, read noise) may be negative; the
        // black level keeps them inside the ADC range.
        const float value = std::nearbyint(black + gain * (charge + dsnu[x] + read));
        out[x] = static_cast<uint16_t>(std::min(std::max(value, 0.0f), max_dn));
      }
    }
  });
  return dn;
}

cv::Mat SensorModel::ToOutput(const cv::Mat& raw_dn) const {
  if (tone_lut_.empty()) return raw_dn.clone();  // linear, > 8 bits: 16-bit PNG of raw DN
  cv::Mat out(raw_dn.size(), CV_8UC1);
  const uint8_t* lut = tone_lut_.ptr<uint8_t>(0);
  for (int y = 0; y < raw_dn.rows; ++y) {
    const uint16_t* in = raw_dn.ptr<uint16_t>(y);
    uint8_t* o = out.ptr<uint8_t>(y);
    for (int x = 0; x < raw_dn.cols; ++x) o[x] = lut[in[x]];
  }
  return out;
}

}  // namespace irbench
