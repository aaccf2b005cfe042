#pragma once
// What the tracker reads of a sequence folder: the calibration
// (calib/intri.yml, calib/extri.yml: OpenCV FileStorage, EasyMocap layout;
// image sizes and fps from calib/cameras.json), the screens as a real
// installation would survey them (calib/screens.json), the empty-stage frames
// (background/<cam>/) and the frames (frames/<cam>/). Never truth/ and never the
// manifest (which names the avatar and motion): a real rig has neither.
//
// Or a recording (docs/recordings.md): one video per camera, videos/<cam>.<ext>
// (any format OpenCV's video I/O reads), the empty stage as background/<cam>.<ext>
// or a time range of the videos, and the calibration as EasyMocap's
// intri.yml and extri.yml (in calib/ or the folder itself; image sizes and
// fps then come from the videos). A rendered sequence written with
// `irbench render --video` is both.

#include <filesystem>
#include <memory>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "geometry/camera.h"
#include "geometry/screen.h"
#include "sequence_format/calibration.h"

namespace irbench {

// How to open a folder: its frame files, or its videos.
struct SequenceInputOptions {
  // Read videos/ even when frames/ is there (a folder without frames/ is
  // read from its videos anyway).
  bool videos = false;
  // The empty stage as [from, to) seconds of the videos, when there are no
  // background videos.
  std::optional<std::pair<double, double>> empty_stage_s;
};

class SequenceInput {
 public:
  // Throws InputError naming the file and field: a missing or unreadable
  // calibration, a camera without any frame, a gap in the empty-stage frames
  // or cameras with different numbers of them. Frames may be missing (a rig
  // that lost some): the sequence runs to the last frame of any camera, and
  // MissingFrames() says what is not there.
  // From videos: an unreadable video, one of the wrong size (against
  // calib/cameras.json when present) or cameras with different numbers of
  // frames are InputErrors naming the video.
  static SequenceInput Open(const std::filesystem::path& dir, const SequenceInputOptions& options = {});

  // A live rig's folder (`irbench live --capture`, docs/live.md): the
  // calibration as for a recording (calib/cameras.json with calib/intri.yml
  // and extri.yml, or EasyMocap's intri.yml and extri.yml in calib/ or the
  // folder itself) and calib/screens.json; no frames (frame_count() is 0:
  // they come from the capture, capture_input.h). Then UseCaptureFormat, and
  // the empty stage from UseEmptyStage or OpenEmptyStageVideos.
  static SequenceInput OpenRig(const std::filesystem::path& dir);
  // The capture's image sizes and frame rate, per camera in the cameras'
  // order: they become the cameras' where no calib/cameras.json gives them;
  // where one does, a size that differs is an InputError on --capture naming
  // the camera's device (`devices`).
  void UseCaptureFormat(const std::vector<cv::Size>& sizes, double fps, const std::vector<std::string>& devices);
  // The empty stage as captured: per camera (the cameras' order) its frames,
  // the same number for each; `sources` names each camera's device (the
  // front end's errors name it).
  void UseEmptyStage(std::vector<std::vector<cv::Mat>> frames, std::vector<std::string> sources);
  // The empty stage from background/<cam>.<ext> videos in the folder;
  // InputError when there are none (naming --empty-stage as the other way)
  // or one is of another size than its camera.
  void OpenEmptyStageVideos();

  const std::filesystem::path& dir() const { return dir_; }
  const std::vector<Camera>& cameras() const { return cameras_; }
  int frame_count() const { return frame_count_; }
  int background_count() const { return background_count_; }
  double fps() const { return timing_.empty() ? 30.0 : timing_.front().fps; }
  // The projection screens as surveyed (calib/screens.json; empty when the
  // file is absent): geometry and named targets.
  const std::vector<ScreenSurface>& screens() const { return screens_; }

  // 8-bit single-channel images (16-bit frames are scaled to 8 bits). Throws
  // InputError for an unreadable file or one of the wrong size.
  cv::Mat Frame(int camera, int frame) const;
  // Every camera's frame `frame`, in the cameras' order (a frame-set).
  std::vector<cv::Mat> FrameSet(int frame) const;
  // The same, tolerating faults: an empty Mat for a camera whose frame is
  // missing, undecodable or of the wrong size, with the reason in `problems`
  // (one entry per camera, empty when the frame was read).
  std::vector<cv::Mat> TryFrameSet(int frame, std::vector<std::string>* problems) const;
  // Per camera, how many frames below frame_count() have no file.
  const std::vector<int>& MissingFrames() const { return missing_frames_; }
  cv::Mat Background(int camera, int index) const;
  std::vector<cv::Mat> Backgrounds(int camera) const;

  // The frame's file; from videos, the camera's video; for a captured empty
  // stage, the camera's device.
  std::filesystem::path FramePath(int camera, int frame) const;
  std::filesystem::path BackgroundPath(int camera, int index) const;
  bool from_videos() const { return !videos_.empty(); }

 private:
  struct Video;  // one camera's video, read forwards
  static void OpenVideos(SequenceInput& in, const SequenceInputOptions& options);
  // The calibration and screens of a recording or a live rig.
  static void ReadRig(SequenceInput& in);
  // One video per camera from `folder` (<cam>.<ext>), all of the same length;
  // none when `required` is false and the first camera has none.
  std::vector<std::shared_ptr<Video>> OpenCameraVideos(const std::filesystem::path& folder, bool required) const;
  cv::Mat Load(const std::filesystem::path& path, int camera) const;
  cv::Mat LoadVideoFrame(Video& video, int index, int camera) const;

  std::filesystem::path dir_;
  std::vector<Camera> cameras_;
  std::vector<CameraTiming> timing_;
  std::vector<ScreenSurface> screens_;
  int frame_count_ = 0;
  int background_count_ = 0;
  std::vector<int> missing_frames_;
  // From videos: per camera, the frames' video and the empty stage's (the
  // same one, from `background_first_`, when given as a time range).
  std::vector<std::shared_ptr<Video>> videos_, background_videos_;
  int background_first_ = 0;
  // A live rig: whether calib/cameras.json gave the sizes, and the empty
  // stage as captured (per camera) with each camera's device.
  bool has_cameras_json_ = false;
  std::vector<std::vector<cv::Mat>> held_backgrounds_;
  std::vector<std::string> held_background_sources_;
};

}  // namespace irbench
