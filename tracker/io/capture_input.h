#pragma once
// A live rig's cameras (`irbench live --capture CAM=DEVICE`, docs/live.md):
// one OpenCV capture per calibrated camera — a V4L2 device by index or path,
// a network stream's URL, or anything else cv::VideoCapture opens (a video
// file plays as a camera that never waits) — read one frame-set at a time.

#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/videoio.hpp>

#include "geometry/camera.h"

namespace irbench {

// One camera's source, as given on the command line.
struct CaptureSource {
  std::string camera;  // a camera of the rig's calibration
  std::string device;  // "0" (an index), "/dev/video2", "rtsp://...", a file
};

// "CAM=DEVICE"; InputError on field `--capture` otherwise.
CaptureSource ParseCaptureSource(const std::string& text);

class CaptureRig {
 public:
  // Opens every camera's source, in the cameras' order, and reads one
  // frame-set from them (which Read() then returns first) to learn each
  // image's size. InputError on field --capture naming the camera or device:
  // a camera of the calibration without a source, a source for a camera the
  // calibration lacks or a second one for the same camera, a device that
  // cannot be opened or gives no first frame.
  CaptureRig(const std::vector<Camera>& cameras, const std::vector<CaptureSource>& sources);

  // Per camera, the size of its first frame.
  const std::vector<cv::Size>& sizes() const { return sizes_; }
  // The frame rate the first camera's device reports (0 when it reports none).
  double fps() const { return fps_; }
  const std::string& device(int camera) const { return devices_.at(camera); }

  // The next frame-set, 8-bit grey, in the cameras' order: every camera's
  // frame grabbed first, then each decoded, so their exposures lie as close
  // together as the devices allow. A camera that gives no frame, or one of
  // another size than its first, has an empty Mat and the reason in
  // `problems` (one entry per camera, empty when read): the tracker leaves it
  // out as a camera that lost a frame. False, and nothing read, once no
  // camera gives a frame (the streams ended).
  bool Read(std::vector<cv::Mat>* images, std::vector<std::string>* problems);

 private:
  std::vector<std::string> devices_;
  std::vector<cv::VideoCapture> captures_;
  std::vector<cv::Size> sizes_;
  double fps_ = 0;
  std::vector<cv::Mat> first_;  // the frame-set read when opening
  bool first_pending_ = false;
};

}  // namespace irbench
