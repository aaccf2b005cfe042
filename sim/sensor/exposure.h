#pragma once
// The exposure of a rig's frames: each camera's clean render (its radiance
// per light source) through the illumination's flicker, the lens (optics.h)
// and the sensor (sensor_model.h) to the written frame, with capture faults
// (dropped frames, rolling shutter) and the truth of what was applied.
// Motion blur's sub-frames are rendered by the caller and come in summed.

#include <cstddef>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "geometry/camera.h"
#include "sequence_format/calibration.h"
#include "sim/sensor/flicker.h"
#include "sim/sensor/optics.h"
#include "sim/sensor/sensor_model.h"

namespace irbench {

// One camera's clean render as the sensor chain reads it: the renderer's
// images, passed as plain images so that sim/sensor stays below sim/render.
struct CleanRender {
  const cv::Mat& grey;      // CV_8UC1, written as is by a camera without a sensor model
  const cv::Mat& radiance;  // CV_32FC4, relative radiance per source (docs/sensor.md)
  const cv::Mat& depth;     // CV_32FC1, camera z in metres; empty unless rendered
};

// The sensor chains of every camera of a rig over one sequence, with the
// state a dropped frame repeats (the last written image and its flicker).
class RigExposure {
 public:
  // cameras[c] with setups[c]; active[c] false: the camera writes its clean
  // render as is. The flicker's seeded events span [start_s, end_s] (s).
  // Builds each camera's sensor model, flicker model and optics in that order.
  RigExposure(const std::vector<Camera>& cameras,
              const std::vector<CameraTiming>& timing,
              const std::vector<SensorSetup>& setups,
              const std::vector<bool>& active,
              uint64_t seed,
              double start_s,
              double end_s);

  // Turns camera c's render (its radiance per source, or their mean over the
  // exposure's sub-frames, `radiance_sum` / `samples`) into the written frame:
  // the illuminators' light follows the mains, the screens' content light the
  // content's flicker, each row its own with a rolling shutter; the 940 nm
  // light counts by the sensor's relative quantum efficiency. A `sweep` level
  // of 0 or more replaces the content's (the calibration sweep of empty-stage
  // frames). `t`: the frame's instant (s), the exposure's centre. Records the
  // levels, exposure and drops in `sensor_truth` under the camera's name.
  // Calls for different cameras may run at once, each with its own
  // `sensor_truth` object.
  cv::Mat Expose(size_t c,
                 const CleanRender& render,
                 const cv::Mat& radiance_sum,
                 int samples,
                 double t,
                 uint64_t noise_frame,
                 nlohmann::json& sensor_truth,
                 double sweep = -1);

  // Forgets the last written images: the next frame of each camera cannot be
  // a dropped one (between the empty-stage frames and the sequence).
  void ForgetLastFrames();

 private:
  // One camera's chain and the state a dropped frame repeats.
  struct CameraChain {
    CameraChain(const Camera& camera,
                double exposure_ms,
                const SensorSetup& camera_setup,
                bool is_active,
                uint64_t seed,
                double start_s,
                double end_s);
    std::string name;
    double exposure_ms;
    SensorSetup setup;
    bool active;
    SensorModel sensor;
    FlickerModel flicker;
    Optics optics;
    cv::Mat radiance;  // the weighted radiance (CV_32FC1), reused frame to frame
    cv::Mat last_written;
    double last_flicker = 1.0;  // of the image a drop repeats
  };

  // Weighs `sources` (CV_32FC4) by the mains level `mains` and the screens'
  // level `screen` (per row with a rolling shutter, over the exposure from
  // `start_s`, `exposure_s` long) into chain.radiance; returns the
  // flicker: the lit image's mean relative to the steady light's.
  double WeighSources(CameraChain& chain,
                      const cv::Mat& sources,
                      double start_s,
                      double exposure_s,
                      double mains,
                      double screen,
                      double sweep);

  uint64_t seed_;
  std::vector<CameraChain> chains_;
};

}  // namespace irbench
