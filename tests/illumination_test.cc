// The near-IR illumination through the whole render path: the illuminators'
// light follows the mains, the screens' content light the content's flicker,
// each on its own; a rolling shutter bands the mains row by row. Cameras
// are set up to read radiance exactly (no noise, linear 16-bit DN).

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "sim/sensor/flicker.h"
#include "sim/sequence/render_job.h"
#include "sequence_format/manifest.h"
#include "tests/test_util.h"
#include "tests/track_figures.h"

namespace irbench {
namespace {
namespace fs = std::filesystem;
using irbench::testing::ReadJsonLines;
using irbench::testing::FreshTempDir;
using irbench::testing::ReadText;
using irbench::testing::WriteText;

// A camera override that reads radiance without noise: 16-bit linear DN,
// 51,000 DN at radiance 1 over the rig's 8 ms, no dark signal.
nlohmann::json ExactSensor(const nlohmann::json& flicker, const nlohmann::json& capture) {
  return {{"sensor",
           {{"noise", false}, {"bit_depth", 16}, {"system_gain_dn_per_e", 10.0}, {"full_well_e", 1e7},
            {"dark_current_e_per_s", 0.0}}},
          {"flicker", flicker},
          {"capture", capture}};
}

// An empty theater stage (background frames) whose side camera sees both the
// illuminators' light and the screen's content light, both flickering: each
// frame's mean is a m(t) + b s(t) with the truth's levels, both sources show,
// and the truth's "flicker" is that mean over a + b.
TEST(IlluminationTest, ScreenContentAndIlluminatorsFlickerApart) {
  const fs::path dir = FreshTempDir("illum_split");
  auto rig = nlohmann::json::parse(ReadText(std::string(IRBENCH_SOURCE_DIR) + "/rigs/theater4.json"));
  rig["cameras"][3]["sensor"] = ExactSensor(
      {{"screen_amplitude", 0.3}, {"cut_rate_hz", 40.0}, {"fade_s", 0.001}, {"mains_hz", 50.0}, {"mains_depth", 0.4}},
      nlohmann::json::object());
  WriteText(dir / "rig.json", rig.dump());
  RenderJobOptions options;
  options.rig = (dir / "rig.json").string();
  options.motion = "stand";
  options.frames = 1;
  options.background_frames = 40;
  options.screen_sweep = false;  // the content's own flicker, not the calibration sweep
  options.out = dir / "seq";
  const fs::path seq = RunRenderJob(options);
  const std::vector<nlohmann::json> truth = ReadJsonLines(seq / "truth/background.jsonl");
  ASSERT_EQ(truth.size(), 40u);
  Eigen::MatrixXd a(40, 2);
  Eigen::VectorXd mean(40), recorded(40);
  double m_lo = 9, m_hi = 0, s_lo = 9, s_hi = 0;
  for (int f = 0; f < 40; ++f) {
    char name[32];
    std::snprintf(name, sizeof(name), "background/side/%06d.png", f);
    const cv::Mat image = cv::imread((seq / name).string(), cv::IMREAD_UNCHANGED);
    ASSERT_EQ(image.type(), CV_16UC1);
    const nlohmann::json& s = truth[f]["sensor"]["side"];
    const double m = s["illuminators"], screen = s["screen"];
    a(f, 0) = m;
    a(f, 1) = screen;
    mean[f] = cv::mean(image)[0];
    recorded[f] = s["flicker"];
    m_lo = std::min(m_lo, m), m_hi = std::max(m_hi, m), s_lo = std::min(s_lo, screen), s_hi = std::max(s_hi, screen);
  }
  // The levels vary independently and enough to separate the sources.
  ASSERT_GT(m_hi - m_lo, 0.1);
  ASSERT_GT(s_hi - s_lo, 0.3);
  const Eigen::Vector2d ab = a.colPivHouseholderQr().solve(mean);
  const Eigen::VectorXd residual = a * ab - mean;
  const double rms = std::sqrt(residual.squaredNorm() / 40);
  EXPECT_LT(rms, 0.002 * mean.mean()) << "residual " << rms;
  EXPECT_GT(ab[0], 0.1 * ab.sum()) << "the illuminators' light";
  EXPECT_GT(ab[1], 0.1 * ab.sum()) << "the screen's content light";
  for (int f = 0; f < 40; ++f) EXPECT_NEAR(recorded[f], mean[f] / ab.sum(), 0.003) << "frame " << f;
  std::printf("side camera, empty stage: mean DN = %.1f m + %.1f s (content share %.2f), residual rms %.2f DN\n",
              ab[0], ab[1], ab[1] / ab.sum(), rms);
}

// The empty-stage frames are filmed while the screens sweep their brightness:
// the truth records the ramp's levels, every camera sees the stage brighten
// with them, and the manifest says so. Without a sensor model (the clean
// preset) nothing flickers, and there is no sweep.
TEST(IlluminationTest, EmptyStageFramesSweepTheScreens) {
  const fs::path dir = FreshTempDir("illum_sweep");
  for (const std::string sensor : {"thesis", "clean"}) {
    RenderJobOptions options;
    options.motion = "stand";
    options.sensor = sensor;
    options.frames = 1;
    options.background_frames = 3;
    options.out = dir / sensor;
    const fs::path seq = RunRenderJob(options);
    const nlohmann::json manifest = ReadManifest(seq).json;
    const std::vector<nlohmann::json> truth = ReadJsonLines(seq / "truth/background.jsonl");
    ASSERT_EQ(truth.size(), 3u);
    const bool sweep = sensor != "clean";
    if (sweep) {
      EXPECT_EQ(manifest["background_screen_sweep"]["from"], 0.25);
      EXPECT_EQ(manifest["background_screen_sweep"]["to"], 1.75);
    } else {
      EXPECT_TRUE(manifest["background_screen_sweep"].is_null());
    }
    for (const std::string cam : {"front_left", "front_right", "side", "overhead"}) {
      std::vector<double> means;
      for (int f = 0; f < 3; ++f) {
        EXPECT_DOUBLE_EQ(truth[f]["sensor"][cam]["screen"].get<double>(), sweep ? 0.25 + 0.75 * f : 1.0)
            << cam << " frame " << f;
        char name[64];
        std::snprintf(name, sizeof(name), "background/%s/%06d.png", cam.c_str(), f);
        means.push_back(cv::mean(cv::imread((seq / name).string(), cv::IMREAD_GRAYSCALE))[0]);
      }
      if (sweep) {
        // The screens' light on the stage: at least a third of a grey level
        // across the ramp, above what the grain does to a frame's mean.
        EXPECT_GT(means[1], means[0] + 0.15) << cam;
        EXPECT_GT(means[2], means[1] + 0.15) << cam;
      } else {
        EXPECT_EQ(means[0], means[2]) << cam;
      }
    }
  }
}

// A room lit by one illuminator on a 100 Hz supply, read by a camera whose
// rolling shutter spans 20 ms: each row's level against the same render
// without the mains modulation is the mains' mean over that row's exposure.
TEST(IlluminationTest, RollingShutterBandsFollowTheMains) {
  const fs::path dir = FreshTempDir("illum_rolling");
  WriteText(dir / "room.json", R"({"format": "irbench.scene/1", "name": "room", "ambient": 0.0, "bounce": false,
    "objects": [{"type": "room", "name": "hall", "min": [-5, -5, 0], "max": [5, 5, 4],
                 "floor": 0.5, "ceiling": 0.5, "walls": 0.5}],
    "lights": [{"name": "lamp", "position": [0, -3, 3.5], "look_at": [0, 0, 0], "cone_deg": 170,
                "power": 8, "shadows": false}]})");
  const nlohmann::json mains = {{"mains_hz", 100.0}, {"mains_depth", 0.5}};
  auto render = [&](const std::string& name, const nlohmann::json& flicker, const nlohmann::json& capture) {
    auto rig = nlohmann::json::parse(ReadText(std::string(IRBENCH_SOURCE_DIR) + "/rigs/theater4.json"));
    rig["cameras"][3]["sensor"] = ExactSensor(flicker, capture);
    WriteText(dir / (name + "_rig.json"), rig.dump());
    RenderJobOptions options;
    options.rig = (dir / (name + "_rig.json")).string();
    options.scene = (dir / "room.json").string();
    options.motion = "stand";
    options.frames = 1;
    options.background_frames = 2;
    options.out = dir / name;
    const fs::path seq = RunRenderJob(options);
    cv::Mat image = cv::imread((seq / "background/side/000001.png").string(), cv::IMREAD_UNCHANGED);
    image.convertTo(image, CV_64F);
    return image;
  };
  const cv::Mat steady = render("steady", nlohmann::json::object(), nlohmann::json::object());
  const cv::Mat rolling = render("rolling", mains, {{"rolling_shutter_ms", 20.0}});
  const cv::Mat global = render("global", mains, nlohmann::json::object());
  // The same flicker model the render used: seed 1, from the first background frame.
  const double fps = 30;
  FlickerParams params;
  params.mains_hz = 100;
  params.mains_depth = 0.5;
  const FlickerModel flicker(params, 1, -2 / fps, 1 / fps);
  const double exposure_s = 0.008, t = 1 / fps - 2 / fps;
  double lo = 9, hi = 0, worst = 0, global_spread = 0;
  const double global_level = cv::sum(global)[0] / cv::sum(steady)[0];
  for (int y = 0; y < steady.rows; ++y) {
    const double row = cv::sum(rolling.row(y))[0] / cv::sum(steady.row(y))[0];
    const double row_start = t - 0.5 * exposure_s + (double(y) / (steady.rows - 1) - 0.5) * 0.020;
    const double expected = flicker.MainsMean(row_start, exposure_s);
    worst = std::max(worst, std::abs(row - expected));
    lo = std::min(lo, row), hi = std::max(hi, row);
    global_spread = std::max(global_spread,
                             std::abs(cv::sum(global.row(y))[0] / cv::sum(steady.row(y))[0] - global_level));
  }
  EXPECT_LT(worst, 0.002);
  EXPECT_GT(hi - lo, 0.15) << "bands";
  EXPECT_LT(global_spread, 0.001) << "a global shutter has no bands";
  EXPECT_NEAR(global_level, flicker.MainsMean(t - 0.5 * exposure_s, exposure_s), 0.002);
  std::printf("rolling shutter: row levels %.3f..%.3f, worst row off the mains model by %.5f\n", lo, hi, worst);
}


// The flicker bar through the whole render path: an empty theater lit only by
// its screen's projected content (illuminators off), seen by one camera with
// a noisy linear sensor. The relative std of the per-frame mean signal over
// 300 frames matches the configured amplitude within 10 %; with flicker off
// it stays under the noise floor of a frame mean.
TEST(IlluminationTest, ScreenLitStageFlickersWithTheConfiguredAmplitude) {
  const fs::path dir = FreshTempDir("illum_amplitude");
  auto scene = nlohmann::json::parse(ReadText(std::string(IRBENCH_SOURCE_DIR) + "/scenes/theater.json"));
  scene["lights"] = nlohmann::json::array();
  scene["ambient"] = 0.0;
  WriteText(dir / "dark_theater.json", scene.dump());
  const double amplitude = 0.1;
  auto frame_means = [&](const std::string& name, const nlohmann::json& flicker, double* pixel_var) {
    auto rig = nlohmann::json::parse(ReadText(std::string(IRBENCH_SOURCE_DIR) + "/rigs/theater4.json"));
    nlohmann::json camera = rig["cameras"][3];
    camera["sensor"] = {{"sensor", {{"noise", true}, {"bit_depth", 12}, {"system_gain_dn_per_e", 0.5}, {"black_level_dn", 64}}},
                        {"flicker", flicker}};
    rig["cameras"] = nlohmann::json::array({camera});
    WriteText(dir / (name + "_rig.json"), rig.dump());
    RenderJobOptions options;
    options.rig = (dir / (name + "_rig.json")).string();
    options.scene = (dir / "dark_theater.json").string();
    options.motion = "stand";
    options.frames = 1;
    options.background_frames = 300;
    options.screen_sweep = false;  // the content's own flicker, not the calibration sweep
    options.out = dir / name;
    const fs::path seq = RunRenderJob(options);
    std::vector<double> means;
    cv::Mat previous;
    *pixel_var = 0;
    for (int f = 0; f < 300; ++f) {
      char file[32];
      std::snprintf(file, sizeof(file), "background/side/%06d.png", f);
      cv::Mat image = cv::imread((seq / file).string(), cv::IMREAD_UNCHANGED);
      image.convertTo(image, CV_64F);
      means.push_back(cv::mean(image)[0] - 64);
      if (f == 1) {
        // Temporal noise of one pixel, from two frames' difference.
        cv::Scalar m, sd;
        cv::meanStdDev(image - previous, m, sd);
        *pixel_var = sd[0] * sd[0] / 2;
      }
      previous = image;
    }
    return means;
  };
  auto relative_std = [](const std::vector<double>& x, double* std_out) {
    double m = 0, v = 0;
    for (double y : x) m += y;
    m /= x.size();
    for (double y : x) v += (y - m) * (y - m);
    *std_out = std::sqrt(v / (x.size() - 1));
    return *std_out / m;
  };
  double var = 0, sd = 0;
  const std::vector<double> flickering = frame_means(
      "flicker", {{"screen_amplitude", amplitude}, {"cut_rate_hz", 100.0}, {"fade_s", 0.001}}, &var);
  const double measured = relative_std(flickering, &sd);
  EXPECT_NEAR(measured, amplitude, 0.1 * amplitude);
  const std::vector<double> steady = frame_means("steady", nlohmann::json::object(), &var);
  double steady_sd = 0;
  relative_std(steady, &steady_sd);
  const double floor = std::sqrt(var / (320.0 * 240.0));
  EXPECT_LT(steady_sd, 1.5 * floor);
  std::printf("screen-lit empty stage: relative std of the frame mean %.4f (configured %.4f); steady %.4f DN "
              "(noise floor of a frame mean %.4f DN)\n",
              measured, amplitude, steady_sd, floor);
}

}  // namespace
}  // namespace irbench
