#pragma once
// A sweep's pose axis (sweep_spec.h PoseAxis): read from the spec, and a
// point's pose written as a motion file that any suite or `irbench render
// --motion` can reuse: a keyframe motion (irbench.keyframes/1) for joint
// rotations, a session of the library's `posture` (irbench.session/1) for
// atoms' weights.

#include <filesystem>
#include <string>
#include <vector>

#include "ci/sweep/sweep_spec.h"
#include "common/json_reader.h"

namespace irbench {

// `{"pose": NAME, "joints": {"right_shoulder": [x, y, z], ...}, "move_s",
// "hold_s"}` or `{"pose": NAME, "atoms": {"right": {"A1": w, ...}, "left":
// ...}, ...}`, each component a number or `{"from", "to", "steps"}`
// (`steps` needed in a grid where from and to differ). Throws InputError
// naming the field (an unknown joint, arm or atom, a range beyond ±360
// degrees or, for a weight, 0..1; for atoms a hold over 60 s).
PoseAxis ReadPoseAxis(const JsonNode& axis, bool grid);

// The point's motion. Joints: standing (arms down) at 0, the pose at
// move_s, held to move_s + hold_s; joints the pose does not list stay as
// when standing; `values` per dim, degrees. Atoms: the library's `posture`
// with the weights (`values` per dim, clamped to 0..1), which stands at
// rest, moves and holds at the person's tempo and rests again in 1 s.
// Written to `file` (atomically).
void WritePoseMotion(const PoseAxis& pose, const std::vector<double>& values, const std::string& name,
                     const std::string& description, const std::filesystem::path& file);

}  // namespace irbench
