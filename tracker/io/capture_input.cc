#include "tracker/io/capture_input.h"

#include <algorithm>
#include <cmath>
#include <map>

#include <opencv2/core/utils/logger.hpp>

#include "common/error.h"
#include "tracker/io/grey_frame.h"

namespace irbench {
namespace {

bool IsIndex(const std::string& device) {
  return !device.empty() && device.size() <= 4 && device.find_first_not_of("0123456789") == std::string::npos;
}

void Open(cv::VideoCapture& capture, const std::string& camera, const std::string& device) {
  // OpenCV tries its backends in turn and logs each one's failure: the one
  // error line below says it instead.
  const cv::utils::logging::LogLevel level = cv::utils::logging::getLogLevel();
  cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_SILENT);
  bool opened = false;
  try {
    opened = IsIndex(device) ? capture.open(std::stoi(device), cv::CAP_ANY) : capture.open(device, cv::CAP_ANY);
  } catch (const cv::Exception& e) {
    cv::utils::logging::setLogLevel(level);
    throw InputError(device, "--capture", "camera '" + camera + "': cannot be opened: " + e.msg);
  }
  cv::utils::logging::setLogLevel(level);
  if (!opened || !capture.isOpened()) {
    throw InputError(device, "--capture", "camera '" + camera + "': cannot be opened as a capture device or stream");
  }
}

// The camera's decoded frame, or an empty Mat with the reason.
cv::Mat Retrieve(cv::VideoCapture& capture, const std::string& device, std::string* problem) {
  cv::Mat frame;
  try {
    if (capture.retrieve(frame) && !frame.empty()) return GreyFrame(frame);
  } catch (const cv::Exception& e) {
    *problem = device + ": frame cannot be decoded: " + e.msg;
    return {};
  }
  *problem = device + ": frame cannot be decoded";
  return {};
}

}  // namespace

CaptureSource ParseCaptureSource(const std::string& text) {
  const size_t eq = text.find('=');
  if (eq == std::string::npos || eq == 0 || eq + 1 == text.size()) {
    throw InputError("", "--capture", "expected CAMERA=DEVICE (e.g. front_left=/dev/video0), got '" + text + "'");
  }
  return {text.substr(0, eq), text.substr(eq + 1)};
}

CaptureRig::CaptureRig(const std::vector<Camera>& cameras, const std::vector<CaptureSource>& sources) {
  std::map<std::string, std::string> device_of;
  for (const CaptureSource& s : sources) {
    const bool known = std::any_of(cameras.begin(), cameras.end(), [&](const Camera& c) { return c.name == s.camera; });
    if (!known) {
      std::string names;
      for (const Camera& c : cameras) names += (names.empty() ? "" : ", ") + c.name;
      throw InputError("", "--capture", "no camera '" + s.camera + "' in the calibration (it has " + names + ")");
    }
    if (!device_of.emplace(s.camera, s.device).second) {
      throw InputError("", "--capture", "camera '" + s.camera + "' given twice");
    }
  }
  for (const Camera& c : cameras) {
    const auto it = device_of.find(c.name);
    if (it == device_of.end()) {
      throw InputError("", "--capture", "no source for camera '" + c.name + "' (--capture " + c.name + "=DEVICE)");
    }
    devices_.push_back(it->second);
  }
  captures_.resize(cameras.size());
  for (size_t c = 0; c < cameras.size(); ++c) Open(captures_[c], cameras[c].name, devices_[c]);
  fps_ = captures_[0].get(cv::CAP_PROP_FPS);
  if (!(fps_ > 0 && std::isfinite(fps_))) fps_ = 0;
  std::vector<std::string> problems;
  if (!Read(&first_, &problems)) {
    throw InputError(devices_[0], "--capture", "no camera gave a first frame");
  }
  for (size_t c = 0; c < cameras.size(); ++c) {
    if (first_[c].empty()) throw InputError(devices_[c], "--capture", "camera '" + cameras[c].name + "': " + problems[c]);
    sizes_.push_back(first_[c].size());
  }
  first_pending_ = true;
}

bool CaptureRig::Read(std::vector<cv::Mat>* images, std::vector<std::string>* problems) {
  problems->assign(captures_.size(), "");
  if (first_pending_) {
    first_pending_ = false;
    *images = std::move(first_);
    first_.clear();
    return true;
  }
  std::vector<bool> grabbed(captures_.size());
  bool any = false;
  for (size_t c = 0; c < captures_.size(); ++c) {
    try {
      grabbed[c] = captures_[c].grab();
    } catch (const cv::Exception&) {
      grabbed[c] = false;
    }
    any = any || grabbed[c];
  }
  if (!any) return false;
  images->assign(captures_.size(), cv::Mat());
  for (size_t c = 0; c < captures_.size(); ++c) {
    if (!grabbed[c]) {
      (*problems)[c] = devices_[c] + ": no frame";
      continue;
    }
    cv::Mat image = Retrieve(captures_[c], devices_[c], &(*problems)[c]);
    if (image.empty()) continue;
    if (!sizes_.empty() && image.size() != sizes_[c]) {
      (*problems)[c] = devices_[c] + ": frame is " + std::to_string(image.cols) + "x" + std::to_string(image.rows) +
                       ", the first was " + std::to_string(sizes_[c].width) + "x" + std::to_string(sizes_[c].height);
      continue;
    }
    if (image.depth() != CV_8U) {
      (*problems)[c] = devices_[c] + ": frame is not 8-bit";
      continue;
    }
    (*images)[c] = std::move(image);
  }
  return true;
}

}  // namespace irbench
