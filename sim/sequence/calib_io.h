#pragma once
// Calibration files of a sequence: calib/intri.yml and calib/extri.yml (OpenCV
// FileStorage, EasyMocap key names) and calib/cameras.json.

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "sim/camera/camera.h"
#include "sim/sensor/sensor_model.h"

namespace irbench {

// intri.yml: names, K_<cam> (3x3), dist_<cam> (1x5).
std::string IntriYaml(const std::vector<Camera>& cameras);
// extri.yml: names, R_<cam> (3x1 Rodrigues), Rot_<cam> (3x3), T_<cam> (3x1 m);
// all cam_from_world.
std::string ExtriYaml(const std::vector<Camera>& cameras);
// cameras.json: the same plus image size, fps, exposure, sensor parameters.
nlohmann::json CamerasJson(const std::vector<Camera>& cameras, const std::vector<SensorSetup>& sensors);

}  // namespace irbench
