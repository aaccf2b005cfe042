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
  // Per camera, the rig file's "up" (default +z): the world direction its
  // view was levelled by (cam_from_world keeps only the image's up).
  std::vector<Eigen::Vector3d> up;
  // Per camera, the "sensor" object of the rig file (knob overrides of the
  // sensor preset: {"sensor": {...}, "flicker": {...}}), or null.
  std::vector<nlohmann::json> sensor_overrides;
  std::filesystem::path source;
};

// Physical ranges of a rig's numbers, beyond the format's own checks:
// fx in [kMinFocalPerPixel, kMaxFocalPerPixel] x width, fy the same x height
// (fields of view from about 0.6 to 178 degrees);
inline constexpr double kMinFocalPerPixel = 0.01;
inline constexpr double kMaxFocalPerPixel = 100.0;
// |each distortion coefficient| <= this (the presets use <= 0.22);
inline constexpr double kMaxDistortionCoefficient = 100.0;
// |each coordinate| of position, look_at and up <= this, metres.
inline constexpr double kMaxRigCoordinateM = 1000.0;

// Loads and validates a rig; every problem throws InputError naming the file and
// field (e.g. "cameras[1].fx: must be positive"). Camera names must pass
// CameraNameProblem (sequence_format/calibration.h): [A-Za-z0-9_-], 1-64
// characters, not starting with '-'.
Rig LoadRig(const std::filesystem::path& path);

// Checks that the distortion does not fold inside the image and that every
// border pixel undistorts. Returns an error message or "".
std::string CheckDistortionUsable(const Camera& camera);

}  // namespace irbench
