#include "sim/sensor/exposure.h"

namespace irbench {

RigExposure::CameraChain::CameraChain(const Camera& camera,
                                      double camera_exposure_ms,
                                      const SensorSetup& camera_setup,
                                      bool is_active,
                                      uint64_t seed,
                                      double start_s,
                                      double end_s)
    : name(camera.name),
      exposure_ms(camera_exposure_ms),
      setup(camera_setup),
      active(is_active),
      sensor(camera_setup.sensor, seed, camera.name, camera.width, camera.height),
      flicker(camera_setup.flicker, seed, start_s, end_s),
      optics(camera_setup.optics, camera) {}

RigExposure::RigExposure(const std::vector<Camera>& cameras,
                         const std::vector<CameraTiming>& timing,
                         const std::vector<SensorSetup>& setups,
                         const std::vector<bool>& active,
                         uint64_t seed,
                         double start_s,
                         double end_s)
    : seed_(seed) {
  chains_.reserve(cameras.size());
  for (size_t c = 0; c < cameras.size(); ++c) {
    chains_.emplace_back(cameras[c], timing[c].exposure_ms, setups[c], active[c], seed, start_s, end_s);
  }
}

cv::Mat RigExposure::Expose(size_t c,
                            const CleanRender& render,
                            const cv::Mat& radiance_sum,
                            int samples,
                            double t,
                            uint64_t noise_frame,
                            nlohmann::json& sensor_truth,
                            double sweep) {
  CameraChain& chain = chains_[c];
  if (!chain.active) {
    sensor_truth[chain.name] = {{"flicker", 1.0},
                                {"screen", 1.0},
                                {"illuminators", 1.0},
                                {"exposure_ms", chain.exposure_ms},
                                {"dropped", false}};
    return render.grey;
  }
  const SensorSetup& setup = chain.setup;
  // The exposure is centred on the frame time, where the truth is; with a
  // rolling shutter, the middle row's is.
  const double exposure_s = chain.exposure_ms / 1000.0;
  const double start_s = t - 0.5 * exposure_s;
  const double mains = chain.flicker.MainsMean(start_s, exposure_s);
  const double screen = sweep >= 0 ? sweep : chain.flicker.ScreenMean(start_s, exposure_s);
  const double drop_u = UniformFromHash(MixHash(seed_, 0xD50Bull + c), noise_frame);
  const bool dropped = drop_u < setup.capture.drop_rate && !chain.last_written.empty();
  nlohmann::json& truth = sensor_truth[chain.name];
  // A dropped frame repeats the last image, and its illumination.
  truth = {{"flicker", chain.last_flicker},
           {"screen", screen},
           {"illuminators", mains},
           {"exposure_ms", chain.exposure_ms},
           {"dropped", dropped}};
  if (dropped) return chain.last_written;
  const cv::Mat sources = samples > 1 ? cv::Mat(radiance_sum / samples) : render.radiance;
  chain.last_flicker = WeighSources(chain, sources, start_s, exposure_s, mains, screen, sweep);
  truth["flicker"] = chain.last_flicker;
  const cv::Mat seen = chain.optics.Apply(chain.radiance, render.depth);
  chain.last_written =
      chain.sensor.ToOutput(chain.sensor.Expose(seen, chain.exposure_ms, noise_frame));
  return chain.last_written;
}

double RigExposure::WeighSources(CameraChain& chain,
                                 const cv::Mat& sources,
                                 double start_s,
                                 double exposure_s,
                                 double mains,
                                 double screen,
                                 double sweep) {
  const SensorSetup& setup = chain.setup;
  const double qe = setup.sensor.quantum_efficiency;
  const float q940 = qe > 0 ? static_cast<float>(setup.sensor.quantum_efficiency_940 / qe) : 0.0f;
  const float q_content = 0.5f * (1.0f + q940);
  const double readout_s = setup.capture.rolling_shutter_ms / 1000.0;
  const cv::Scalar mean = cv::mean(sources);
  const double steady = mean[0] + q940 * mean[1] + q_content * mean[2] + mean[3];
  double lit = 0;
  if (readout_s <= 0 || sources.rows < 2) {
    const float m = static_cast<float>(mains), s = static_cast<float>(screen);
    const cv::Matx14f weights(m, m * q940, s * q_content, 1.0f);
    cv::transform(sources, chain.radiance, weights);
    lit = mains * (mean[0] + q940 * mean[1]) + screen * q_content * mean[2] + mean[3];
  } else {
    chain.radiance.create(sources.size(), CV_32FC1);
    for (int y = 0; y < sources.rows; ++y) {
      const double row_start = start_s + (double(y) / (sources.rows - 1) - 0.5) * readout_s;
      const float m = static_cast<float>(chain.flicker.MainsMean(row_start, exposure_s));
      const float s =
          static_cast<float>(sweep >= 0 ? sweep : chain.flicker.ScreenMean(row_start, exposure_s));
      const cv::Vec4f* in_row = sources.ptr<cv::Vec4f>(y);
      float* out_row = chain.radiance.ptr<float>(y);
      double row_sum = 0;
      for (int x = 0; x < sources.cols; ++x) {
        const cv::Vec4f& v = in_row[x];
        out_row[x] = m * (v[0] + q940 * v[1]) + s * q_content * v[2] + v[3];
        row_sum += out_row[x];
      }
      lit += row_sum / (double(sources.rows) * sources.cols);
    }
  }
  return steady > 0 ? lit / steady : 1.0;
}

void RigExposure::ForgetLastFrames() {
  for (CameraChain& chain : chains_) chain.last_written.release();
}

}  // namespace irbench
