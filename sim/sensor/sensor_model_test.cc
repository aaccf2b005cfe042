#include "sim/sensor/sensor_model.h"

#include <gtest/gtest.h>

#include <cmath>

#include "common/error.h"
#include "sim/sensor/emva1288.h"
#include "sim/sensor/flicker.h"

namespace irbench {
namespace {

constexpr int kWidth = 320, kHeight = 240;

// A 12-bit sensor so that quantisation noise stays small against the dark
// noise, as the EMVA 1288 method assumes.
SensorParams TestSensor() {
  SensorParams p;
  p.photons_per_ms = 2000;
  p.quantum_efficiency = 0.5;
  p.full_well_e = 6000;
  p.system_gain_dn_per_e = 0.5;
  p.dark_noise_e = 8;
  p.dark_current_e_per_s = 100;
  p.dsnu_e = 5;
  p.prnu = 0.02;
  p.bit_depth = 12;
  p.black_level_dn = 64;
  return p;
}

cv::Mat Flat(float radiance) { return cv::Mat(kHeight, kWidth, CV_32FC1, cv::Scalar(radiance)); }

cv::Mat AsDouble(const cv::Mat& m) {
  cv::Mat d;
  m.convertTo(d, CV_64F);
  return d;
}

double Mean(const cv::Mat& m) { return cv::mean(m)[0]; }
double Variance(const cv::Mat& m) {
  cv::Scalar mean, std;
  cv::meanStdDev(m, mean, std);
  return std[0] * std[0];
}

// EMVA 1288 photon transfer: flat-field and dark pairs at 12 exposure times.
// The slope of temporal variance against mean signal (both dark-corrected)
// is the system gain K; the dark variance gives the dark noise; averages of
// many frames give DSNU and PRNU.
TEST(SensorModelTest, PhotonTransferRecoversTheConfiguredSensor) {
  const SensorParams p = TestSensor();
  const SensorModel sensor(p, 42, "cam0", kWidth, kHeight);
  std::vector<double> exposures_ms;
  for (int level = 0; level < 12; ++level) exposures_ms.push_back(0.25 + 0.4 * level);  // 250 .. 4650 e-
  const PhotonTransfer ptc = MeasurePhotonTransfer(sensor, Flat(1.0f), Flat(0.0f), exposures_ms, 0);
  uint64_t frame = ptc.frames_used;
  const double gain = ptc.gain_dn_per_e;
  EXPECT_NEAR(gain, p.system_gain_dn_per_e, 0.03 * p.system_gain_dn_per_e);
  // Dark noise at the shortest exposure includes the shot noise of its dark current.
  const double dark_noise = ptc.dark_noise_e;
  const double expected_dark =
      std::sqrt(p.dark_noise_e * p.dark_noise_e + p.dark_current_e_per_s * exposures_ms[0] / 1000);
  EXPECT_NEAR(dark_noise, expected_dark, 0.05 * expected_dark);

  // Spatial non-uniformities from averages of 32 frames (temporal variance
  // divided by 32 is removed, as EMVA 1288 prescribes).
  const int n = 32;
  const double exposure_ms = 2.5;
  cv::Mat dark_sum = cv::Mat::zeros(kHeight, kWidth, CV_64F), bright_sum = dark_sum.clone();
  for (int i = 0; i < n; ++i) {
    dark_sum += AsDouble(sensor.Expose(Flat(0.0f), exposure_ms, frame++));
    bright_sum += AsDouble(sensor.Expose(Flat(1.0f), exposure_ms, frame++));
  }
  const cv::Mat dark_avg = dark_sum / n, bright_avg = bright_sum / n;
  const double temporal_dark_var = gain * gain * (p.dark_noise_e * p.dark_noise_e +
                                                  p.dark_current_e_per_s * exposure_ms / 1000) + 1.0 / 12;
  const double dsnu = std::sqrt(Variance(dark_avg) - temporal_dark_var / n) / gain;
  EXPECT_NEAR(dsnu, p.dsnu_e, 0.10 * p.dsnu_e);
  const double signal = Mean(bright_avg) - Mean(dark_avg);
  const double temporal_bright_var = temporal_dark_var + gain * signal;
  const double prnu = std::sqrt(Variance(bright_avg - dark_avg) - (temporal_bright_var + temporal_dark_var) / n -
                                (Variance(dark_avg) - temporal_dark_var / n)) / signal;
  EXPECT_NEAR(prnu, p.prnu, 0.10 * p.prnu);
  std::printf("photon transfer: K %.4f (%.4f) DN/e-, dark noise %.2f (%.2f) e-, DSNU %.2f (%.2f) e-, "
              "PRNU %.4f (%.4f)\n",
              gain, p.system_gain_dn_per_e, dark_noise, expected_dark, dsnu, p.dsnu_e, prnu, p.prnu);
}

TEST(SensorModelTest, SameSeedSameBytesDifferentSeedsUncorrelated) {
  const SensorParams p = TestSensor();
  const cv::Mat scene = Flat(0.5f);
  const SensorModel a(p, 7, "cam0", kWidth, kHeight), a2(p, 7, "cam0", kWidth, kHeight);
  const SensorModel b(p, 8, "cam0", kWidth, kHeight);
  const cv::Mat fa = a.Expose(scene, 4.0, 3), fa2 = a2.Expose(scene, 4.0, 3), fb = b.Expose(scene, 4.0, 3);
  EXPECT_EQ(cv::norm(fa, fa2, cv::NORM_INF), 0.0);
  cv::Mat x = AsDouble(fa) - Mean(fa), y = AsDouble(fb) - Mean(fb);
  const double r = x.dot(y) / std::sqrt(x.dot(x) * y.dot(y));
  EXPECT_LT(std::abs(r), 0.01) << r;
  // Consecutive frames of one camera are independent too.
  cv::Mat z = AsDouble(a.Expose(scene, 4.0, 4)) - AsDouble(fa);
  EXPECT_GT(Variance(z), 0.0);
}

// The std of the screen-driven level matches the configured amplitude, and a
// static camera's per-frame mean follows it; with flicker off the mean stays
// within the noise floor.
TEST(FlickerTest, AmplitudeOfPerFrameMeanMatchesConfiguration) {
  FlickerParams f;
  f.screen_amplitude = 0.1;
  f.cut_rate_hz = 8;
  f.fade_s = 0.01;
  const double fps = 30, exposure_s = 0.008;
  const int frames = 3000;
  const FlickerModel flicker(f, 5, 0.0, frames / fps);
  SensorParams p = TestSensor();
  const SensorModel sensor(p, 5, "cam0", 64, 48);
  // A static "empty stage": a fixed gradient of radiance.
  cv::Mat stage(48, 64, CV_32FC1);
  for (int y = 0; y < 48; ++y)
    for (int x = 0; x < 64; ++x) stage.at<float>(y, x) = 0.2f + 0.5f * x / 64;
  std::vector<double> means;
  const SensorModel dark_sensor(p, 5, "cam0", 64, 48);
  const double dark_mean = Mean(AsDouble(dark_sensor.Expose(cv::Mat::zeros(48, 64, CV_32FC1), 8.0, 99999)));
  for (int i = 0; i < frames; ++i) {
    const double level = flicker.Level(i / fps, exposure_s);
    means.push_back(Mean(AsDouble(sensor.Expose(stage * level, 8.0, i))) - dark_mean);
  }
  double m = 0, v = 0;
  for (double x : means) m += x;
  m /= frames;
  for (double x : means) v += (x - m) * (x - m);
  const double relative_std = std::sqrt(v / (frames - 1)) / m;
  EXPECT_NEAR(relative_std, f.screen_amplitude, 0.1 * f.screen_amplitude);

  // Flicker off: the per-frame mean varies only by the temporal noise of a mean.
  const FlickerModel steady(FlickerParams{}, 5, 0.0, frames / fps);
  std::vector<double> steady_means;
  for (int i = 0; i < 300; ++i) {
    steady_means.push_back(Mean(AsDouble(sensor.Expose(stage * steady.Level(i / fps, exposure_s), 8.0, i))));
  }
  double sm = 0, sv = 0;
  for (double x : steady_means) sm += x;
  sm /= steady_means.size();
  for (double x : steady_means) sv += (x - sm) * (x - sm);
  const double steady_std = std::sqrt(sv / (steady_means.size() - 1));
  // Noise floor of a 64x48 mean: per-pixel temporal std / sqrt(N), with margin.
  const double pixel_var = p.system_gain_dn_per_e * (m / 1.0) + std::pow(p.system_gain_dn_per_e * p.dark_noise_e, 2);
  EXPECT_LT(steady_std, 1.5 * std::sqrt(pixel_var / (64 * 48)));
  std::printf("flicker: relative std of the per-frame mean %.4f (configured %.4f); steady %.4f DN\n",
              relative_std, f.screen_amplitude, steady_std);
}

TEST(FlickerTest, MainsBeatsAgainstTheExposure) {
  FlickerParams f;
  f.mains_hz = 100;
  f.mains_depth = 0.2;
  const FlickerModel flicker(f, 1, 0.0, 10.0);
  // An exposure of whole mains periods averages the modulation away.
  for (double t : {0.0, 0.013, 0.5}) EXPECT_NEAR(flicker.Level(t, 0.01), 1.0, 1e-9);
  // A short exposure sees it.
  double lo = 2, hi = 0;
  for (int i = 0; i < 100; ++i) {
    const double level = flicker.Level(i * 0.001, 0.0005);
    lo = std::min(lo, level), hi = std::max(hi, level);
  }
  EXPECT_GT(hi - lo, 0.3);
}

TEST(SensorPresetTest, PresetsAndOverrides) {
  for (const char* name : {"clean", "thesis", "harsh"}) {
    const auto setup = SensorPreset(name);
    ASSERT_TRUE(setup.has_value()) << name;
    EXPECT_NO_THROW(setup->sensor.Check("", ""));
    EXPECT_NO_THROW(setup->flicker.Check("", ""));
  }
  EXPECT_FALSE(SensorPreset("foggy").has_value());
  SensorSetup setup = *SensorPreset("thesis");
  ApplySensorOverrides(nlohmann::json::parse(R"({"sensor": {"dark_noise_e": 3}, "flicker": {"mains_hz": 120}})"),
                       "rig.json", "cameras[0].sensor", &setup);
  EXPECT_EQ(setup.sensor.dark_noise_e, 3);
  EXPECT_EQ(setup.flicker.mains_hz, 120);
  try {
    ApplySensorOverrides(nlohmann::json::parse(R"({"sensor": {"prnu": 2}})"), "rig.json",
                         "cameras[0].sensor", &setup);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "cameras[0].sensor.sensor.prnu");
  }
}

// Issue 27.3: an integer knob beyond int wrapped into range (4294967304 read
// as 8 bits); every knob is range-checked, non-finite ones included.
TEST(SensorPresetTest, OverridesOutsideTheirRangeNameTheKnob) {
  auto field_of = [](const std::string& text) {
    SensorSetup setup = *SensorPreset("thesis");
    try {
      ApplySensorOverrides(nlohmann::json::parse(text), "rig.json", "cameras[0].sensor", &setup);
    } catch (const InputError& e) {
      return e.field();
    }
    return std::string("(no error)");
  };
  EXPECT_EQ(field_of(R"({"sensor": {"bit_depth": 4294967304}})"), "cameras[0].sensor.sensor.bit_depth");
  EXPECT_EQ(field_of(R"({"optics": {"motion_blur_samples": -4294967295}})"),
            "cameras[0].sensor.optics.motion_blur_samples");
  EXPECT_EQ(field_of(R"({"sensor": {"photons_per_ms": 1e308}})"), "cameras[0].sensor.sensor.photons_per_ms");
  EXPECT_EQ(field_of(R"({"flicker": {"mains_hz": -1e-300}})"), "cameras[0].sensor.flicker.mains_hz");
  EXPECT_EQ(field_of(R"({"sensor": {"bit_depth": 12}})"), "(no error)");
}

}  // namespace
}  // namespace irbench
