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

CameraReference ReferenceFromEmptyStage(const std::vector<cv::Mat>& frames) {
  CameraReference r;
  double sum = 0;
  for (const cv::Mat& image : frames) sum += cv::mean(image)[0];
  r.mean_level = frames.empty() ? 0.0 : sum / frames.size();
  // Noisy when every consecutive pair differs in 5 % of the pixels or more
  // (the thesis preset: about half of them; the clean preset: none).
  r.noisy = frames.size() >= 2;
  for (size_t i = 1; i < frames.size() && r.noisy; ++i) {
    if (frames[i].size() != frames[i - 1].size() || frames[i].type() != frames[i - 1].type()) continue;
    cv::Mat diff;
    cv::absdiff(frames[i], frames[i - 1], diff);
    r.noisy = cv::countNonZero(diff.reshape(1)) >= 0.05 * diff.total() * diff.channels();
  }
  return r;
}

CameraHealthMonitor::CameraHealthMonitor(std::vector<CameraReference> references, const CameraHealthOptions& options)
    : options_(options), references_(std::move(references)) {
  options_.Check();
  previous_.resize(references_.size());
  repeats_.assign(references_.size(), 0);
}

std::vector<CameraStatus> CameraHealthMonitor::Update(const std::vector<cv::Mat>& frames) {
  const size_t n = references_.size();
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
    if (s.mean_level < options_.dark_max_level && s.mean_level < options_.dark_ratio * references_[c].mean_level) {
      s.health = CameraHealth::kDark;
    } else if (references_[c].noisy && repeats_[c] >= options_.frozen_frames) {
      s.health = CameraHealth::kFrozen;
    }
  }
  return status;
}

}  // namespace irbench
