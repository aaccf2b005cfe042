#pragma once
// A sweep's rig axes (docs/sweeps.md): value axes whose key starts with
// `rig.` change every point's rig rather than a scenario key:
//   rig.cameras      which of the rig's cameras are used: a list of names, or
//                    n for the first n (the camera count); at least 2
//   rig.resolution   [width, height] of every camera, the intrinsics scaled
//                    with it (the same field of view and distortion)
//   rig.focal_scale  every camera's fx and fy times this (a zoom: < 1 wider)
//   rig.dist         every camera's lens distortion [k1, k2, p1, p2, k3]
// and the sensor knobs, `sensor.<group>.<knob>` (docs/sensor.md's groups
// sensor, flicker, optics, capture): every camera's sensor override of that
// knob (the rig's `cameras[i].sensor`) set to the value, on top of the
// point's preset.
// A point's rig is the base rig (or the `rig` axis's) with the placements
// applied first, then the rig.* keys in the order above, then the knobs in
// the spec's order.

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

namespace irbench {

// The rig.* keys, in the order they are applied.
const std::vector<std::string>& RigAxisKeys();
// `sensor.<group>.<knob>`, both names non-empty.
bool IsSensorKnobKey(const std::string& key);
// A rig.* key or a sensor knob.
bool IsRigAxisKey(const std::string& key);

// Applies one rig axis's value to a rig file's JSON (irbench.rig/1). Throws
// InputError (empty file, the field "value") for a value of the wrong shape or
// a camera the rig lacks; the result is checked by LoadRig, not here.
void ApplyRigAxis(const std::string& key, const nlohmann::json& value, nlohmann::json* rig);

// The rig file's JSON with the (key, value) pairs applied in order, loaded and checked as a rig file
// would be (LoadRig, through a scratch file) and, for a sensor knob, each
// camera's sensor overrides applied to each of `presets` (the sensor presets
// a point may have) as a render would: "" or what is wrong, e.g.
// "cameras[1].fx: focal length must be positive".
std::string RigAxisProblem(const std::filesystem::path& rig_file,
                           const std::vector<std::pair<std::string, nlohmann::json>>& values,
                           const std::vector<std::string>& presets);

}  // namespace irbench
