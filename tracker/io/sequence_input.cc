#include "tracker/io/sequence_input.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgcodecs.hpp>

#include "common/error.h"
#include "sequence_format/calibration.h"
#include "sequence_format/screens.h"

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

}  // namespace

SequenceInput SequenceInput::Open(const fs::path& dir) {
  SequenceInput in;
  in.dir_ = dir;
  if (!fs::is_directory(dir)) throw InputError(dir.string(), "", "no such sequence folder");
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
  char name[32];
  std::snprintf(name, sizeof(name), "%06d.png", frame);
  return dir_ / "frames" / cameras_.at(camera).name / name;
}

fs::path SequenceInput::BackgroundPath(int camera, int index) const {
  char name[32];
  std::snprintf(name, sizeof(name), "%06d.png", index);
  return dir_ / "background" / cameras_.at(camera).name / name;
}

cv::Mat SequenceInput::Load(const fs::path& path, int camera) const {
  cv::Mat image = cv::imread(path.string(), cv::IMREAD_UNCHANGED);
  if (image.empty()) throw InputError(path.string(), "", "unreadable image");
  if (image.channels() != 1) throw InputError(path.string(), "", "expected a single-channel (grey) image");
  const Camera& cam = cameras_.at(camera);
  if (image.cols != cam.width || image.rows != cam.height) {
    throw InputError(path.string(), "",
                     "image is " + std::to_string(image.cols) + "x" + std::to_string(image.rows) +
                         ", calibration says " + std::to_string(cam.width) + "x" + std::to_string(cam.height));
  }
  if (image.depth() == CV_16U) image.convertTo(image, CV_8U, 1.0 / 257.0);
  if (image.depth() != CV_8U) throw InputError(path.string(), "", "expected 8- or 16-bit pixels");
  return image;
}

cv::Mat SequenceInput::Frame(int camera, int frame) const { return Load(FramePath(camera, frame), camera); }

std::vector<cv::Mat> SequenceInput::TryFrameSet(int frame, std::vector<std::string>* problems) const {
  std::vector<cv::Mat> out(cameras_.size());
  problems->assign(cameras_.size(), "");
  for (size_t c = 0; c < cameras_.size(); ++c) {
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
  return Load(BackgroundPath(camera, index), camera);
}

std::vector<cv::Mat> SequenceInput::Backgrounds(int camera) const {
  std::vector<cv::Mat> out;
  for (int i = 0; i < background_count_; ++i) out.push_back(Background(camera, i));
  return out;
}

}  // namespace irbench
