#pragma once
// The procedural motion library after the thesis (5.3, 7.1): the six gestures,
// the atom postures and their two-arm combinations, pointing at named screen
// targets, natural story-telling hand motions, rest, crouch, walking, entering,
// leaving and turning. Motions are built for one avatar (its skeleton) in one
// scene (its screens and stage) and one person's style, starting where the
// previous motion left the person. Names and parameters in docs/motion.md.

#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "sim/body/avatar.h"
#include "sim/motion/motion_source.h"
#include "sim/scene/scene.h"

namespace irbench {

// How a person moves, seeded: two persons with the same gesture differ.
struct MotionStyle {
  double tempo = 1.0;         // speed factor (> 1 faster)
  double amplitude = 1.0;     // scales arm excursions from rest
  double asynchrony_s = 0.0;  // the second arm lags the first by this much
  double tremor_deg = 0.0;    // amplitude of the physiological arm tremor
  double tremor_hz = 9.0;
  int handedness = +1;        // +1 right-handed, -1 left-handed
  double rest_abduction_deg = 8;  // how far the resting arms hang from the body
  uint64_t seed = 1;
};

// The style of a named person: drawn from a hash of the name and the seed, so
// it is the same on every machine. `overrides` (an avatar file's "style"
// object; null for none) sets fields by name; bad ones are InputErrors naming
// `file` and "style.<field>".
MotionStyle StyleFor(const std::string& person, uint64_t seed, const nlohmann::json& overrides = nullptr,
                     const std::string& file = "");

// Where the person is when a motion starts, updated to where it ends.
struct StageState {
  Eigen::Vector2d position = Eigen::Vector2d::Zero();  // pelvis over the floor, world x, y
  double heading_deg = 0;                              // 0 faces +y (the screen)
  bool on_stage = true;
};

struct MotionContext {
  const Avatar* avatar = nullptr;
  const Scene* scene = nullptr;  // may be null: pointing then needs explicit points
  MotionStyle style;
  StageState state;
};

// Builds library motion `name` with parameters `params` (a JSON object, or
// null). Throws InputError(file, field) naming `where` on bad names or
// parameters. Updates ctx.state to the motion's end.
MotionPtr BuildLibraryMotion(const std::string& name, const nlohmann::json& params, MotionContext& ctx,
                             const std::string& file = "", const std::string& where = "motion");

// The library's motion names, with a one-line description each.
std::vector<std::pair<std::string, std::string>> LibraryMotions();

// The six gestures of the thesis (5.3), ids 1..6 in order.
const std::vector<std::string>& GestureNames();

// The five posture atoms (docs/motion.md) by name: "A0".."A4" give 0..4,
// any other name -1. kPostureAtomNames lists them for error messages.
int PostureAtomIndex(const std::string& name);
extern const char* const kPostureAtomNames;

}  // namespace irbench
