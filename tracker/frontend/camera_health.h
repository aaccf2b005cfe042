#pragma once
// Per-camera health over a sequence (issue 27): the faults a real rig has, a
// camera that goes black, one that freezes on a frame, one that loses frames.
// A camera in a bad state is left out of the hull, the 3D axis points and the
// pose likelihood for as long as it is bad and taken back the first frame it
// is good again. Decided from the frames alone (and the empty-stage frames'
// brightness), never from truth.

#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace irbench {

enum class CameraHealth {
  kOk,
  kMissing,  // no readable frame (missing file, undecodable, wrong size)
  kDark,     // the frame is black: far darker than the empty stage ever is
  kFrozen,   // the same bytes as its previous frames while other cameras changed
};
const char* CameraHealthName(CameraHealth health);

struct CameraHealthOptions {
  // Dark: the frame's mean below `dark_ratio` x the empty-stage frames' mean
  // (and below `dark_max_level` grey levels). The thesis preset's flicker and
  // a person in view move the mean by a few tens of per cent, never by 80.
  double dark_ratio = 0.2;
  double dark_max_level = 16;
  // Frozen: byte-identical to the camera's previous frame on this many
  // consecutive frame-sets in which some other camera's frame changed; only
  // for a camera whose sensor shows noise (CameraReference::noisy).
  int frozen_frames = 2;
  // false: report the states but use every readable frame (a missing frame
  // is always left out: there is nothing to use).
  bool leave_out = true;
  void Check() const;  // throws InputError naming the field
};

// What the health monitor knows of a camera from its empty-stage frames: their
// mean grey level, and whether its sensor shows noise (consecutive empty-stage
// frames differ in at least 5 % of their pixels). A noise-free camera (the
// sim's `clean` preset) repeats its frame whenever nothing moves in its view,
// so a frozen one cannot be told from a still one: it is never called frozen.
struct CameraReference {
  double mean_level = 0;
  bool noisy = false;
};
CameraReference ReferenceFromEmptyStage(const std::vector<cv::Mat>& empty_stage_frames);

struct CameraStatus {
  CameraHealth health = CameraHealth::kOk;
  double mean_level = 0;  // the frame's mean grey level (0 when missing)
  bool usable() const { return health == CameraHealth::kOk; }
};

class CameraHealthMonitor {
 public:
  // `references`: per camera, from its empty-stage frames.
  CameraHealthMonitor(std::vector<CameraReference> references, const CameraHealthOptions& options = {});

  // One frame-set in order: per camera an 8-bit image, or an empty Mat for a
  // frame that could not be read. Returns each camera's state for this set.
  std::vector<CameraStatus> Update(const std::vector<cv::Mat>& frames);

 private:
  CameraHealthOptions options_;
  std::vector<CameraReference> references_;
  std::vector<cv::Mat> previous_;
  std::vector<int> repeats_;  // consecutive identical frames while others changed
};


}  // namespace irbench
