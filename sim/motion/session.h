#pragma once
// Resolving `--motion` (a library name, a file in motions/, a keyframe or
// session JSON file, a BVH or AMC clip) into one motion, and session scripts
// (irbench.session/1) that sequence motions: enter, point at the helicopter,
// wave, rest, crouch, leave. Format in docs/motion.md.

#include <filesystem>
#include <string>

#include "sim/motion/library.h"
#include "sim/motion/motion_source.h"

namespace irbench {

struct ResolvedMotion {
  MotionPtr motion;
  std::string kind;  // "library", "keyframes", "session", "bvh", "amc"
  std::filesystem::path file;  // empty for library motions
};

// `option` names the command-line option in errors ("--motion").
ResolvedMotion ResolveMotion(const std::string& spec, MotionContext& ctx, const std::string& option);

// Loads a session script; clip and keyframe paths are relative to its folder.
MotionPtr LoadSession(const std::filesystem::path& path, MotionContext& ctx);

}  // namespace irbench
