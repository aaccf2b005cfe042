#pragma once
// Camera faults a real rig has, put into a copy of a rendered sequence
// (`irbench fault`): a camera that goes black, one that freezes on a frame,
// one that loses frames, one whose files are corrupt. The copy's truth is the
// original's: the person did not change, only what the cameras delivered.
// The faults are recorded in the copy's faults.json (the tracker never reads
// it).

#include <filesystem>
#include <string>
#include <vector>

namespace irbench {

enum class CameraFaultKind {
  kBlack,    // the frames are all zero (a dead sensor, a cable pulled)
  kFreeze,   // every frame repeats the first frame of the span
  kDrop,     // the frame files are missing
  kCorrupt,  // the frame files are truncated (undecodable)
};

struct CameraFault {
  std::string camera;
  CameraFaultKind kind = CameraFaultKind::kBlack;
  double from_s = 0, to_s = 0;  // frames with from_s <= f / fps < to_s
};

// Parses "CAMERA:KIND:FROM-TO" (seconds; KIND black|freeze|drop|corrupt),
// e.g. "cam2:black:2-8". Throws InputError naming `option`.
CameraFault ParseCameraFault(const std::string& text, const std::string& option);

struct FaultJobOptions {
  std::filesystem::path sequence;
  std::filesystem::path out;
  std::vector<CameraFault> faults;
  bool overwrite = false;
};

// Writes the faulty copy (files the faults leave alone are hard links where
// the file system allows, copies otherwise); returns its folder. Throws
// InputError for an unknown camera, a span outside the sequence, an output
// inside the input.
std::filesystem::path RunFaultJob(const FaultJobOptions& options);

}  // namespace irbench
