#pragma once
// A sequence folder's calibration (docs/architecture.md, "A sequence folder"):
// calib/intri.yml and calib/extri.yml (OpenCV FileStorage in EasyMocap's
// layout) and calib/cameras.json. The one writer (the sim's render job) and
// the one reader (the tracker, the harness, tests): the file names and keys
// are spelled here only.

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "geometry/camera.h"

namespace irbench {

// Paths inside a sequence folder.
inline constexpr char kIntriFile[] = "calib/intri.yml";
inline constexpr char kExtriFile[] = "calib/extri.yml";
inline constexpr char kCamerasFile[] = "calib/cameras.json";
inline constexpr char kCamerasFormat[] = "irbench.cameras/1";

// Camera names become folder names, file names and FileStorage keys
// (K_<name>), so they are restricted to a safe set: 1 to kMaxCameraNameLength
// characters from [A-Za-z0-9_-], not starting with '-' (no dots, no spaces,
// no slashes, ASCII only).
inline constexpr size_t kMaxCameraNameLength = 64;
// "" when `name` is a valid camera name, else what is wrong with it.
std::string CameraNameProblem(const std::string& name);

// A camera's timing, beside its geometry (Camera): the frame rate and the
// exposure (a sequence's cameras share one clock: the render job checks it).
struct CameraTiming {
  double fps = 30.0;
  double exposure_ms = 10.0;
};

// What a sequence's calibration gives, per camera in `names` order.
struct Calibration {
  std::vector<Camera> cameras;
  std::vector<CameraTiming> timing;
};

// intri.yml: names, K_<cam> (3x3), dist_<cam> (1x5).
std::string IntriYaml(const std::vector<Camera>& cameras);
// extri.yml: names, R_<cam> (3x1 Rodrigues), Rot_<cam> (3x3), T_<cam> (3x1 m);
// all cam_from_world.
std::string ExtriYaml(const std::vector<Camera>& cameras);
// cameras.json: the same plus image size, fps, exposure and, per camera, the
// sensor model's parameters as the sim describes them (`sensors`, one object
// per camera; the reader ignores them).
nlohmann::json CamerasJson(const std::vector<Camera>& cameras,
                           const std::vector<CameraTiming>& timing,
                           const std::vector<nlohmann::json>& sensors);

// Writes the three files under `sequence_dir` (each atomically).
void WriteCalibration(const std::filesystem::path& sequence_dir,
                      const std::vector<Camera>& cameras,
                      const std::vector<CameraTiming>& timing,
                      const std::vector<nlohmann::json>& sensors);

// Reads the cameras of a sequence folder, in intri.yml's `names` order:
// intrinsics and distortion from intri.yml, cam_from_world from extri.yml
// (Rot_ and T_), image size, fps and exposure from cameras.json. Throws
// InputError naming the file and key when one is missing or malformed (a
// rotation that is not one, a focal length <= 0, a NaN, a camera name outside
// the safe set of CameraNameProblem: field "names[i]" of intri.yml, ...).
Calibration ReadCalibration(const std::filesystem::path& sequence_dir);
// EasyMocap's two files alone (a recording's calibration): intrinsics and
// extrinsics per camera; image sizes 0 and default timing, for the caller to
// take from the recording. Throws InputError naming the file and field.
Calibration ReadEasyMocapCalibration(const std::filesystem::path& intri_file,
                                     const std::filesystem::path& extri_file);

}  // namespace irbench
