#pragma once
// The truth's two-arm posture labels (frames.jsonl `labels.posture`,
// docs/truth.md): per arm A0 at rest, else an atom by the elevation of the
// hand tip seen from the shoulder. The sim labels by these bands
// (sim/motion/labels); the tracker's posture proposal reads them back
// (thesis 6.3.2, tracker/pipeline/frame_tracker).

#include <array>
#include <string_view>

namespace irbench {

struct ArmAtomBand {
  std::string_view name;
  double min_deg, max_deg;  // the elevation, degrees above the horizontal
};

inline constexpr std::string_view kRestAtom = "A0";
// Highest first: an arm not at rest is in the first band its elevation reaches.
inline constexpr std::array<ArmAtomBand, 4> kArmAtomBands = {
    {{"A2", 62.5, 90}, {"A3", 22.5, 62.5}, {"A1", -22.5, 22.5}, {"A4", -90, -22.5}}};

}  // namespace irbench
