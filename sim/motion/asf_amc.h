#pragma once
// Acclaim ASF/AMC files as written by the CMU motion-capture database: reading
// a skeleton (.asf) and a motion (.amc) with CRLF, tabs, comments and
// line-numbered errors, and forward kinematics into a MocapClip.
//
// Forward kinematics follows the CMU mocap player (mocapPlayer/amc viewer,
// skeleton.cpp and displaySkeleton.cpp: M_k+1 = M_k · rot_parent_current ·
// R_k+1) and amc2bvh (local · motion · local⁻¹). For bone b with ASF axis
// rotation C_b and AMC motion rotation M_b (both in its local axes), the world
// delta rotation is
//   W_root = C_root · M_root · C_root⁻¹,   W_b = W_parent · C_b · M_b · C_b⁻¹,
// bone b starts where its parent ends (the root: `:root position` plus the AMC
// TX TY TZ) and ends at start_b + W_b · direction_b · length_b.

#include <filesystem>
#include <string>

#include "sim/motion/mocap_clip.h"

namespace irbench {

// CMU captures at 120 Hz; an AMC file does not say its rate.
inline constexpr double kCmuFrameTime = 1.0 / 120.0;

// Physical limits; a value beyond them is refused as an input error (a corrupt
// or crafted file, not a capture). Lengths in file units (CMU: inches / 0.45).
// |ASF position, direction component, bone length| and |AMC translation or
// `l` value|.
inline constexpr double kMaxAsfAmcLength = 1e5;
// |ASF axis / orientation angle| in the file's angle unit, and |AMC rotation|
// in degrees (a :RADIANS file's values are converted first).
inline constexpr double kMaxAsfAmcAngleDeg = 1e6;
// `:units length` (file units per inch × 0.45 in CMU's convention).
inline constexpr double kMinAsfLengthUnit = 1e-4;
inline constexpr double kMaxAsfLengthUnit = 1e4;

// Parses an ASF skeleton file and an AMC motion file into a MocapClip: one
// joint per ASF bone at the bone's start (so "lradius" sits at the elbow, as
// amc2bvh places it), "root", and "<bone>_end" at the tip of every bone without
// children. Positions are in file units (metres_per_unit = 0.0254 / `:units
// length`, the CMU inch convention) and the file's axes; rotations are world
// deltas from the rest pose (every dof zero). `frame_time` in seconds.
// Throws InputError(file, "line N", ...) for any bad input (among them two
// bones with one name, a bone named like another's "<bone>_end" tip, a
// non-finite number or one beyond the limits above), (file, "file", ...) for a
// file that cannot be read.
MocapClip LoadAsfAmc(const std::filesystem::path& asf,
                     const std::filesystem::path& amc,
                     double frame_time = kCmuFrameTime);

// The same from text; the names are used in error messages, and the AMC
// name's stem names the clip.
MocapClip ParseAsfAmc(const std::string& asf_text,
                      const std::string& asf_name,
                      const std::string& amc_text,
                      const std::string& amc_name,
                      double frame_time = kCmuFrameTime);

}  // namespace irbench
