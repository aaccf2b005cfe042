#pragma once
// Projection screens in JSON: the screen entries of a scene file
// (scenes/*.json, docs/formats.md) and a sequence folder's
// calib/screens.json (irbench.screens/1, docs/architecture.md) share one
// parser of a screen's geometry and targets; calib/screens.json has one writer
// (the sim) and one reader (the tracker).

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "common/json_reader.h"
#include "geometry/screen.h"

namespace irbench {

inline constexpr char kScreensFile[] = "calib/screens.json";
inline constexpr char kScreensFormat[] = "irbench.screens/1";

// How a file gives a screen's targets: [s, t] (a scene file) or
// {"screen": [s, t], "world": [x, y, z]} (calib/screens.json, as surveyed).
enum class TargetForm { kScreenCoordinates, kSurveyed };

// A screen's name, type, geometry and targets from a JSON object: a plane's
// `right` and `up` perpendicular (within 1e-3 after normalising: a survey's
// accuracy), a cylinder's angles and heights increasing, every target on the
// screen. `allowed_keys` are accepted (CheckKeys) besides the geometry's own.
// InputError names the field on any bad value.
ScreenSurface ReadScreenSurface(const JsonNode& s,
                                TargetForm target_form,
                                const std::vector<std::string>& allowed_keys);

// One screen as calib/screens.json lists it: the geometry as in the scene
// file, `screen_frame` (a sentence defining s and t), `size` and `targets`
// with their screen and world coordinates.
nlohmann::json ScreenJson(const ScreenSurface& screen);
// The whole calib/screens.json content of a scene's screens.
nlohmann::json ScreensJson(const std::string& scene_name,
                           const std::vector<ScreenSurface>& screens);
void WriteScreens(const std::filesystem::path& sequence_dir,
                  const std::string& scene_name,
                  const std::vector<ScreenSurface>& screens);
// Reads calib/screens.json of a sequence folder; empty when the file is absent
// (a rig without screens). Throws InputError on a malformed file.
std::vector<ScreenSurface> ReadScreens(const std::filesystem::path& sequence_dir);

}  // namespace irbench
