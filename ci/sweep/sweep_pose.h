#pragma once
// A sweep's pose axis (sweep_spec.h PoseAxis): read from the spec, and a
// point's pose written as a keyframe motion (irbench.keyframes/1) that any
// suite or `irbench render --motion` can reuse.

#include <filesystem>
#include <string>
#include <vector>

#include "ci/sweep/sweep_spec.h"
#include "common/json_reader.h"

namespace irbench {

// `{"pose": NAME, "joints": {"right_shoulder": [x, y, z], ...}, "move_s",
// "hold_s"}`, each component a number or `{"from", "to", "steps"}`
// (`steps` needed in a grid where from and to differ). Throws InputError
// naming the field (an unknown joint, a range beyond ±360 degrees).
PoseAxis ReadPoseAxis(const JsonNode& axis, bool grid);

// The point's motion: standing (arms down) at 0, the pose at move_s, held to
// move_s + hold_s; joints the pose does not list stay as when standing.
// Written to `file` (atomically); `values` per dim, degrees.
void WritePoseMotion(const PoseAxis& pose, const std::vector<double>& values, const std::string& name,
                     const std::string& description, const std::filesystem::path& file);

}  // namespace irbench
