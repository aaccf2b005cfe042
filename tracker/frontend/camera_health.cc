#include "tracker/frontend/camera_health.h"

#include <cmath>

#include "common/error.h"

namespace irbench {

const char* CameraHealthName(CameraHealth health) {
  switch (health) {
    case CameraHealth::kOk: return "ok";
    case CameraHealth::kMissing: return "missing";
    case CameraHealth::kDark: return "dark";
    case CameraHealth::kFrozen: return "frozen";
  }
  return "ok";
}

void CameraHealthOptions::Check() const {
  if (!(dark_ratio >= 0 && dark_ratio < 1)) throw InputError("", "health.dark_ratio", "must be in [0, 1)");
  if (!(dark_max_level >= 0 && dark_max_level <= 255)) {
    throw InputError("", "health.dark_max_level", "must be in [0, 255]");
  }
  if (frozen_frames < 1 || frozen_frames > 1000) throw InputError("", "health.frozen_frames", "must be in 1..1000");
}

double MeanLevel(const std::vector<cv::Mat>& images) {
  double sum = 0;
  for (const cv::Mat& image : images) sum += cv::mean(image)[0];
  return images.empty() ? 0.0 : sum / images.size();
}

CameraHealthMonitor::CameraHealthMonitor(std::vector<double> empty_stage_means, const CameraHealthOptions& options)
    : options_(options), empty_stage_means_(std::move(empty_stage_means)) {
  options_.Check();
  previous_.resize(empty_stage_means_.size());
  repeats_.assign(empty_stage_means_.size(), 0);
}

std::vector<CameraStatus> CameraHealthMonitor::Update(const std::vector<cv::Mat>& frames) {
  const size_t n = empty_stage_means_.size();
  if (frames.size() != n) {
    throw InputError("", "frames", "expected " + std::to_string(n) + " frames, got " + std::to_string(frames.size()));
  }
  std::vector<CameraStatus> status(n);
  // Which cameras repeat their previous frame exactly, and whether any
  // readable camera changed.
  std::vector<bool> same(n, false);
  bool any_changed = false;
  for (size_t c = 0; c < n; ++c) {
    if (frames[c].empty()) continue;
    const bool comparable = !previous_[c].empty() && previous_[c].size() == frames[c].size() &&
                            previous_[c].type() == frames[c].type();
    same[c] = comparable && cv::norm(frames[c], previous_[c], cv::NORM_INF) == 0;
    any_changed = any_changed || !same[c];
  }
  for (size_t c = 0; c < n; ++c) {
    CameraStatus& s = status[c];
    if (frames[c].empty()) {
      s.health = CameraHealth::kMissing;
      continue;  // the last readable frame stays the one to compare with
    }
    s.mean_level = cv::mean(frames[c])[0];
    if (!same[c]) {
      repeats_[c] = 0;
    } else if (any_changed) {
      ++repeats_[c];
    }
    previous_[c] = frames[c];
    if (s.mean_level < options_.dark_max_level && s.mean_level < options_.dark_ratio * empty_stage_means_[c]) {
      s.health = CameraHealth::kDark;
    } else if (repeats_[c] >= options_.frozen_frames) {
      s.health = CameraHealth::kFrozen;
    }
  }
  return status;
}

}  // namespace irbench
