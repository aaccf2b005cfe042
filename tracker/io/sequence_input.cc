#include "tracker/io/sequence_input.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "common/error.h"
#include "sequence_format/calibration.h"
#include "sequence_format/screens.h"
#include "tracker/io/grey_frame.h"

namespace irbench {
namespace fs = std::filesystem;
namespace {

// Frames are numbered from 0 without gaps: the count is the first missing one.
int CountNumbered(const fs::path& folder) {
  int n = 0;
  char name[32];
  for (;; ++n) {
    std::snprintf(name, sizeof(name), "%06d.png", n);
    if (!fs::is_regular_file(folder / name)) return n;
  }
}

// The numbers of the frame files present ("%06d.png"), sorted.
std::vector<int> NumberedFiles(const fs::path& folder) {
  std::vector<int> numbers;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(folder, ec)) {
    const std::string name = entry.path().filename().string();
    if (name.size() != 10 || entry.path().extension() != ".png") continue;
    const std::string stem = name.substr(0, 6);
    if (stem.find_first_not_of("0123456789") != std::string::npos) continue;
    numbers.push_back(std::stoi(stem));
  }
  std::sort(numbers.begin(), numbers.end());
  return numbers;
}

// Frames are numbered from 0 without gaps: a gap with later frames behind it
// is an error, not the end of the sequence.
void CheckNoGap(const fs::path& folder, int count) {
  const std::vector<int> numbers = NumberedFiles(folder);
  if (!numbers.empty() && numbers.back() > count) {
    char missing[32];
    std::snprintf(missing, sizeof(missing), "%06d.png", count);
    throw InputError(folder.string(), "", std::string(missing) + " is missing while later frames exist");
  }
}

// The one file in `folder` whose name without extension is `camera`; empty
// when there is none; an error when there are several.
fs::path VideoOf(const fs::path& folder, const std::string& camera) {
  fs::path found;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(folder, ec)) {
    if (!entry.is_regular_file() || entry.path().stem() != camera) continue;
    if (!found.empty()) {
      throw InputError(folder.string(), "",
                       "two videos for camera '" + camera + "': " + found.filename().string() + " and " +
                           entry.path().filename().string());
    }
    found = entry.path();
  }
  return found;
}

// "<what> is WxH, calibration says WxH" when `size` is not the camera's; "".
std::string SizeMismatch(const std::string& what, cv::Size size, const Camera& cam) {
  if (size.width == cam.width && size.height == cam.height) return "";
  return what + " is " + std::to_string(size.width) + "x" + std::to_string(size.height) + ", calibration says " +
         std::to_string(cam.width) + "x" + std::to_string(cam.height);
}

}  // namespace

// One camera's video, decoded forwards; reading an earlier frame reopens it.
struct SequenceInput::Video {
  fs::path path;
  cv::VideoCapture capture;
  int next = 0;  // the index the next read returns
  int count = 0;
  cv::Size size;
  double fps = 0;

  void Reopen() {
    capture.release();
    if (!capture.open(path.string(), cv::CAP_ANY) || !capture.isOpened()) {
      throw InputError(path.string(), "", "cannot be read as a video");
    }
    next = 0;
  }

  // Opens the video and counts its frames by decoding them (container frame
  // counts are estimates for some formats); or, given `same`, a second
  // reader of the same video.
  explicit Video(fs::path file, const Video* same = nullptr) : path(std::move(file)) {
    if (same != nullptr) {
      count = same->count;
      size = same->size;
      fps = same->fps;
      Reopen();
      return;
    }
    try {
      Reopen();
      fps = capture.get(cv::CAP_PROP_FPS);
      cv::Mat frame;
      while (capture.read(frame)) {
        if (count == 0) size = frame.size();
        ++count;
      }
      Reopen();
    } catch (const cv::Exception& e) {
      throw InputError(path.string(), "", "cannot be read as a video: " + e.msg);
    }
    if (count == 0) throw InputError(path.string(), "", "no frames could be decoded");
  }

  cv::Mat Read(int index) {
    if (index < 0 || index >= count) {
      throw InputError(path.string(), "", "no frame " + std::to_string(index) + " (it has " + std::to_string(count) + ")");
    }
    if (index < next) Reopen();
    cv::Mat frame;
    while (next < index) {
      if (!capture.grab()) throw InputError(path.string(), "", "ends before frame " + std::to_string(index));
      ++next;
    }
    if (!capture.read(frame)) throw InputError(path.string(), "", "frame " + std::to_string(index) + " cannot be decoded");
    ++next;
    return frame;
  }
};

void SequenceInput::ReadRig(SequenceInput& in) {
  const fs::path& dir = in.dir_;
  in.has_cameras_json_ = fs::is_regular_file(dir / kCamerasFile);
  if (in.has_cameras_json_) {
    Calibration calibration = ReadCalibration(dir);
    in.cameras_ = std::move(calibration.cameras);
    in.timing_ = std::move(calibration.timing);
  } else {
    const fs::path calib = fs::is_regular_file(dir / kIntriFile) ? dir / "calib" : dir;
    Calibration calibration = ReadEasyMocapCalibration(calib / "intri.yml", calib / "extri.yml");
    in.cameras_ = std::move(calibration.cameras);
    in.timing_ = std::move(calibration.timing);
  }
  in.screens_ = ReadScreens(dir);
  if (in.screens_.empty() && fs::is_regular_file(dir / "screens.json")) {
    throw InputError((dir / "screens.json").string(), "", "screens belong in calib/screens.json");
  }
}

std::vector<std::shared_ptr<SequenceInput::Video>> SequenceInput::OpenCameraVideos(const fs::path& folder,
                                                                                  bool required) const {
  std::vector<std::shared_ptr<Video>> videos;
  for (const Camera& cam : cameras_) {
    const fs::path file = VideoOf(folder, cam.name);
    if (file.empty()) {
      if (!required && videos.empty()) return videos;
      throw InputError(folder.string(), "", "no video for camera '" + cam.name + "' (" + cam.name + ".mkv, .avi, .mp4, ...)");
    }
    videos.push_back(std::make_shared<Video>(file));
  }
  // Every camera the same number of frames: a recording cut short is
  // not a rig that lost frames.
  for (size_t c = 1; c < videos.size(); ++c) {
    if (videos[c]->count != videos[0]->count) {
      const auto& shorter = videos[c]->count < videos[0]->count ? videos[c] : videos[0];
      throw InputError(shorter->path.string(), "",
                       "has " + std::to_string(shorter->count) + " frames; " +
                           (shorter == videos[c] ? videos[0] : videos[c])->path.filename().string() + " has " +
                           std::to_string(std::max(videos[c]->count, videos[0]->count)));
    }
  }
  return videos;
}

void SequenceInput::OpenVideos(SequenceInput& in, const SequenceInputOptions& options) {
  const fs::path& dir = in.dir_;
  ReadRig(in);
  const bool has_cameras_json = in.has_cameras_json_;
  in.videos_ = in.OpenCameraVideos(dir / "videos", true);
  for (size_t c = 0; c < in.cameras_.size(); ++c) {
    Camera& cam = in.cameras_[c];
    const Video& video = *in.videos_[c];
    if (!has_cameras_json) {
      cam.width = video.size.width;
      cam.height = video.size.height;
      if (!(video.fps > 0 && std::isfinite(video.fps))) {
        throw InputError(video.path.string(), "fps", "the video gives no frame rate");
      }
      in.timing_[c].fps = video.fps;
    } else if (const std::string problem = SizeMismatch("video", video.size, cam); !problem.empty()) {
      throw InputError(video.path.string(), "", problem);
    }
  }
  in.frame_count_ = in.videos_[0]->count;
  in.missing_frames_.assign(in.cameras_.size(), 0);
  if (options.empty_stage_s) {
    const auto [from_s, to_s] = *options.empty_stage_s;
    const int first = static_cast<int>(std::lround(from_s * in.fps()));
    const int end = std::min(in.frame_count_, static_cast<int>(std::lround(to_s * in.fps())));
    if (!(from_s >= 0 && to_s > from_s) || end <= first) {
      throw InputError("", "--empty-stage", "no frames of the videos lie in that range");
    }
    in.background_videos_.clear();
    for (const auto& video : in.videos_) in.background_videos_.push_back(std::make_shared<Video>(video->path, video.get()));
    in.background_first_ = first;
    in.background_count_ = end - first;
    return;
  }
  in.OpenEmptyStageVideos();
}

void SequenceInput::OpenEmptyStageVideos() {
  background_videos_ = OpenCameraVideos(dir_ / "background", false);
  if (background_videos_.empty()) {
    throw InputError((dir_ / "background").string(), "",
                     "no empty-stage videos (background/<camera>.mkv, ...); give the empty stage as a time "
                     "range of the videos with --empty-stage FROM:TO (seconds)");
  }
  for (size_t c = 0; c < cameras_.size(); ++c) {
    const Video& video = *background_videos_[c];
    if (!videos_.empty() && video.size != videos_[c]->size) {
      throw InputError(video.path.string(), "", "empty-stage video's size differs from " + videos_[c]->path.filename().string());
    }
    if (const std::string problem = SizeMismatch("empty-stage video", video.size, cameras_[c]); !problem.empty()) {
      throw InputError(video.path.string(), "", problem);
    }
  }
  background_count_ = background_videos_[0]->count;
}

SequenceInput SequenceInput::OpenRig(const fs::path& dir) {
  SequenceInput in;
  in.dir_ = dir;
  if (!fs::is_directory(dir)) throw InputError(dir.string(), "", "no such rig folder");
  ReadRig(in);
  in.missing_frames_.assign(in.cameras_.size(), 0);
  return in;
}

void SequenceInput::UseCaptureFormat(const std::vector<cv::Size>& sizes,
                                     double fps,
                                     const std::vector<std::string>& devices) {
  for (size_t c = 0; c < cameras_.size(); ++c) {
    if (has_cameras_json_) {
      if (const std::string problem = SizeMismatch("its frame", sizes.at(c), cameras_[c]); !problem.empty()) {
        throw InputError(devices.at(c), "--capture", "camera '" + cameras_[c].name + "': " + problem);
      }
      continue;
    }
    cameras_[c].width = sizes.at(c).width;
    cameras_[c].height = sizes.at(c).height;
    timing_[c].fps = fps;
  }
}

void SequenceInput::UseEmptyStage(std::vector<std::vector<cv::Mat>> frames, std::vector<std::string> sources) {
  held_backgrounds_ = std::move(frames);
  held_background_sources_ = std::move(sources);
  background_count_ = held_backgrounds_.empty() ? 0 : static_cast<int>(held_backgrounds_[0].size());
}

SequenceInput SequenceInput::Open(const fs::path& dir, const SequenceInputOptions& options) {
  SequenceInput in;
  in.dir_ = dir;
  if (!fs::is_directory(dir)) throw InputError(dir.string(), "", "no such sequence folder");
  if (options.videos || (!fs::is_directory(dir / "frames") && fs::is_directory(dir / "videos"))) {
    OpenVideos(in, options);
    return in;
  }
  if (options.empty_stage_s) {
    throw InputError("", "--empty-stage", "applies to videos; this sequence has frame files (frames/)");
  }
  Calibration calibration = ReadCalibration(dir);
  in.cameras_ = std::move(calibration.cameras);
  in.timing_ = std::move(calibration.timing);
  in.screens_ = ReadScreens(dir);
  // The empty-stage frames train the background: numbered without gaps and
  // the same count in every camera.
  for (size_t c = 0; c < in.cameras_.size(); ++c) {
    const fs::path folder = dir / "background" / in.cameras_[c].name;
    const int backgrounds = CountNumbered(folder);
    CheckNoGap(folder, backgrounds);
    if (c == 0) {
      in.background_count_ = backgrounds;
    } else if (backgrounds != in.background_count_) {
      throw InputError(folder.string(), "",
                       "camera '" + in.cameras_[c].name + "' has " + std::to_string(backgrounds) +
                           " empty-stage frames; '" + in.cameras_[0].name + "' has " +
                           std::to_string(in.background_count_));
    }
  }
  // The frames may miss some (a rig loses frames): the sequence runs to the
  // last frame of any camera. A camera without any frame is an input error.
  std::vector<std::vector<int>> present(in.cameras_.size());
  for (size_t c = 0; c < in.cameras_.size(); ++c) {
    const fs::path folder = dir / "frames" / in.cameras_[c].name;
    present[c] = NumberedFiles(folder);
    if (present[c].empty()) throw InputError(folder.string(), "", "no frames (000000.png, ...)");
    in.frame_count_ = std::max(in.frame_count_, present[c].back() + 1);
  }
  std::vector<bool> any(in.frame_count_, false);
  for (size_t c = 0; c < in.cameras_.size(); ++c) {
    for (int f : present[c]) any[f] = true;
    in.missing_frames_.push_back(in.frame_count_ - static_cast<int>(present[c].size()));
  }
  // Frame-sets that no camera has, beyond half the sequence: a stray
  // numbered file, not lost frames.
  const int none = static_cast<int>(std::count(any.begin(), any.end(), false));
  if (2 * none > in.frame_count_) {
    char last[32];
    std::snprintf(last, sizeof(last), "%06d.png", in.frame_count_ - 1);
    throw InputError((dir / "frames").string(), "",
                     std::to_string(none) + " of " + std::to_string(in.frame_count_) +
                         " frame-sets have no camera's frame (a stray " + last + "?)");
  }
  return in;
}

fs::path SequenceInput::FramePath(int camera, int frame) const {
  if (from_videos()) return videos_.at(camera)->path;
  char name[32];
  std::snprintf(name, sizeof(name), "%06d.png", frame);
  return dir_ / "frames" / cameras_.at(camera).name / name;
}

fs::path SequenceInput::BackgroundPath(int camera, int index) const {
  if (!held_backgrounds_.empty()) return held_background_sources_.at(camera);
  if (!background_videos_.empty()) return background_videos_.at(camera)->path;
  char name[32];
  std::snprintf(name, sizeof(name), "%06d.png", index);
  return dir_ / "background" / cameras_.at(camera).name / name;
}

cv::Mat SequenceInput::Load(const fs::path& path, int camera) const {
  cv::Mat image = cv::imread(path.string(), cv::IMREAD_UNCHANGED);
  if (image.empty()) throw InputError(path.string(), "", "unreadable image");
  if (image.channels() != 1) throw InputError(path.string(), "", "expected a single-channel (grey) image");
  if (const std::string problem = SizeMismatch("image", image.size(), cameras_.at(camera)); !problem.empty()) {
    throw InputError(path.string(), "", problem);
  }
  if (image.depth() == CV_16U) image.convertTo(image, CV_8U, 1.0 / 257.0);
  if (image.depth() != CV_8U) throw InputError(path.string(), "", "expected 8- or 16-bit pixels");
  return image;
}

cv::Mat SequenceInput::LoadVideoFrame(Video& video, int index, int camera) const {
  cv::Mat image;
  try {
    image = GreyFrame(video.Read(index));
  } catch (const cv::Exception& e) {
    throw InputError(video.path.string(), "", "frame " + std::to_string(index) + " cannot be decoded: " + e.msg);
  }
  const std::string frame = "frame " + std::to_string(index);
  if (const std::string problem = SizeMismatch(frame, image.size(), cameras_.at(camera)); !problem.empty()) {
    throw InputError(video.path.string(), "", problem);
  }
  if (image.depth() != CV_8U) throw InputError(video.path.string(), "", frame + " is not 8-bit");
  return image;
}

cv::Mat SequenceInput::Frame(int camera, int frame) const {
  if (from_videos()) return LoadVideoFrame(*videos_.at(camera), frame, camera);
  return Load(FramePath(camera, frame), camera);
}

std::vector<cv::Mat> SequenceInput::TryFrameSet(int frame, std::vector<std::string>* problems) const {
  std::vector<cv::Mat> out(cameras_.size());
  problems->assign(cameras_.size(), "");
  for (size_t c = 0; c < cameras_.size(); ++c) {
    if (from_videos()) {
      try {
        out[c] = Frame(static_cast<int>(c), frame);
      } catch (const std::exception& e) {
        (*problems)[c] = e.what();
      }
      continue;
    }
    const fs::path path = FramePath(static_cast<int>(c), frame);
    if (!fs::is_regular_file(path)) {
      (*problems)[c] = path.string() + ": missing";
      continue;
    }
    try {
      out[c] = Load(path, static_cast<int>(c));
    } catch (const std::exception& e) {  // InputError, or OpenCV on a mangled file
      (*problems)[c] = e.what();
    }
  }
  return out;
}

std::vector<cv::Mat> SequenceInput::FrameSet(int frame) const {
  std::vector<cv::Mat> out;
  for (size_t c = 0; c < cameras_.size(); ++c) out.push_back(Frame(static_cast<int>(c), frame));
  return out;
}

cv::Mat SequenceInput::Background(int camera, int index) const {
  if (!held_backgrounds_.empty()) return held_backgrounds_.at(camera).at(index);
  if (!background_videos_.empty()) return LoadVideoFrame(*background_videos_.at(camera), background_first_ + index, camera);
  return Load(BackgroundPath(camera, index), camera);
}

std::vector<cv::Mat> SequenceInput::Backgrounds(int camera) const {
  std::vector<cv::Mat> out;
  for (int i = 0; i < background_count_; ++i) out.push_back(Background(camera, i));
  return out;
}

}  // namespace irbench
