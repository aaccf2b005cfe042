#pragma once
// Camera rigs (rigs/*.json): per camera resolution, intrinsics, distortion, a
// pose as position + look-at + up (a Camera), fps and exposure (its
// CameraTiming). Format in docs/formats.md.

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "geometry/camera.h"
#include "sequence_format/calibration.h"

namespace irbench {

struct Rig {
  std::string name;
  std::string scene;  // the scene the rig was designed for (default for --scene)
  std::vector<Camera> cameras;
  std::vector<CameraTiming> timing;  // per camera: fps, exposure
  // Per camera, the "sensor" object of the rig file (knob overrides of the
  // sensor preset: {"sensor": {...}, "flicker": {...}}), or null.
  std::vector<nlohmann::json> sensor_overrides;
  std::filesystem::path source;
};

// Loads and validates a rig; every problem throws InputError naming the file and
// field (e.g. "cameras[1].fx: must be positive").
Rig LoadRig(const std::filesystem::path& path);

// Checks that the distortion does not fold inside the image and that every
// border pixel undistorts. Returns an error message or "".
std::string CheckDistortionUsable(const Camera& camera);

}  // namespace irbench
