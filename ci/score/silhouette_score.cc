#include "ci/score/silhouette_score.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <tuple>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "ci/score/score.h"
#include "common/error.h"
#include "common/logging.h"

namespace irbench {
namespace fs = std::filesystem;
namespace {

using Json = nlohmann::json;

SilhouetteSummary Summarise(const std::vector<const SilhouetteCounts*>& frames) {
  SilhouetteSummary s;
  s.camera_frames = static_cast<int>(frames.size());
  if (frames.empty()) return s;
  std::vector<double> ious;
  long truth = 0, false_px = 0, missed = 0, near = 0;
  for (const SilhouetteCounts* c : frames) {
    ious.push_back(c->iou());
    truth += c->truth;
    false_px += c->false_near + c->false_far;
    missed += c->missed_near + c->missed_far;
    near += c->false_near + c->missed_near;
  }
  std::sort(ious.begin(), ious.end());
  s.iou_median = ious[ious.size() / 2];
  s.iou_p10 = ious[(ious.size() - 1) / 10];  // nearest rank: the ceil(n / 10)-th smallest
  s.iou_min = ious.front();
  s.false_share = truth ? double(false_px) / truth : 0.0;
  s.missed_share = truth ? double(missed) / truth : 0.0;
  if (false_px + missed) s.near_outline_share = double(near) / double(false_px + missed);
  return s;
}

Json SummaryJson(const SilhouetteSummary& s) {
  const auto value = [&](double v) { return s.camera_frames ? Json(v) : Json(nullptr); };
  return {{"camera_frames", s.camera_frames},         {"iou_median", value(s.iou_median)},
          {"iou_p10", value(s.iou_p10)},               {"iou_min", value(s.iou_min)},
          {"false_share", value(s.false_share)},       {"missed_share", value(s.missed_share)},
          {"near_outline_share", s.near_outline_share ? Json(*s.near_outline_share) : Json(nullptr)}};
}

std::string SummaryRow(const std::string& name, const SilhouetteSummary& s) {
  if (s.camera_frames == 0) return "| " + name + " | 0 | – | – | – | – | – |\n";
  return "| " + name + " | " + std::to_string(s.camera_frames) + " | " + Fixed(s.iou_median, 3) + " | " +
         Fixed(s.iou_p10, 3) + " | " + Fixed(100 * s.false_share, 1) + "% | " + Fixed(100 * s.missed_share, 1) +
         "% | " + (s.near_outline_share ? Fixed(100 * *s.near_outline_share, 0) + "%" : std::string("–")) + " |\n";
}

cv::Mat ReadMask(const fs::path& path) {
  const cv::Mat m = cv::imread(path.string(), cv::IMREAD_GRAYSCALE);
  if (m.empty()) throw InputError(path.string(), "", "unreadable image");
  return m;
}

std::vector<fs::path> SortedEntries(const fs::path& dir, bool directories) {
  std::vector<fs::path> out;
  for (const auto& e : fs::directory_iterator(dir)) {
    if (directories ? e.is_directory() : (e.is_regular_file() && e.path().extension() == ".png")) {
      out.push_back(e.path());
    }
  }
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace

double SilhouetteCounts::iou() const {
  const long union_px = truth + false_near + false_far;
  return union_px ? double(intersection()) / union_px : 1.0;
}

SilhouetteCounts CountSilhouette(const cv::Mat& truth, const cv::Mat& silhouette) {
  CV_Assert(truth.type() == CV_8UC1 && silhouette.type() == CV_8UC1 && truth.size() == silhouette.size());
  const cv::Mat in_truth = truth != 0, in_silhouette = silhouette != 0;
  // The 8-neighbourhood: the body grown by a pixel, and shrunk by one with
  // the pixels beyond the image outside it.
  const cv::Mat kernel = cv::Mat::ones(3, 3, CV_8U);
  cv::Mat grown, shrunk;
  cv::dilate(in_truth, grown, kernel);
  cv::erode(in_truth, shrunk, kernel, cv::Point(-1, -1), 1, cv::BORDER_CONSTANT, cv::Scalar(0));
  SilhouetteCounts c;
  c.truth = cv::countNonZero(in_truth);
  c.silhouette = cv::countNonZero(in_silhouette);
  const cv::Mat false_px = in_silhouette & ~in_truth, missed = in_truth & ~in_silhouette;
  c.false_near = cv::countNonZero(false_px & grown);
  c.false_far = cv::countNonZero(false_px) - c.false_near;
  c.missed_far = cv::countNonZero(missed & shrunk);
  c.missed_near = cv::countNonZero(missed) - c.missed_far;
  return c;
}

SilhouetteScore ScoreSilhouettes(const fs::path& masks, const fs::path& silhouettes) {
  SilhouetteScore score;
  score.silhouettes = silhouettes;
  int truth_masks = 0;
  for (const fs::path& camera_dir : SortedEntries(masks, true)) {
    const std::string camera = camera_dir.filename().string();
    for (const fs::path& truth_path : SortedEntries(camera_dir, false)) {
      // The frame number: the whole name but ".png", digits only.
      const std::string stem = truth_path.stem().string();
      int frame = -1;
      const auto [end, error] = std::from_chars(stem.data(), stem.data() + stem.size(), frame);
      if (stem.empty() || error != std::errc() || end != stem.data() + stem.size() || frame < 0 ||
          !std::isdigit(static_cast<unsigned char>(stem[0]))) {
        throw InputError(truth_path.string(), "", "not a frame number (expected 000123.png)");
      }
      ++truth_masks;
      const fs::path silhouette_path = silhouettes / camera / truth_path.filename();
      if (!fs::exists(silhouette_path)) {
        ++score.missing;
        continue;
      }
      const cv::Mat truth = ReadMask(truth_path);
      const cv::Mat silhouette = ReadMask(silhouette_path);
      if (silhouette.size() != truth.size()) {
        throw InputError(silhouette_path.string(), "",
                         "image is " + std::to_string(silhouette.cols) + "x" + std::to_string(silhouette.rows) +
                             ", the truth mask " + std::to_string(truth.cols) + "x" + std::to_string(truth.rows));
      }
      if (cv::countNonZero(truth) == 0) {
        ++score.empty_frames;
        score.empty_false += cv::countNonZero(silhouette);
        continue;
      }
      SilhouetteCounts c = CountSilhouette(truth, silhouette);
      c.camera = camera;
      c.frame = frame;
      score.frames.push_back(c);
    }
  }
  std::sort(score.frames.begin(), score.frames.end(), [](const SilhouetteCounts& a, const SilhouetteCounts& b) {
    return std::tie(a.camera, a.frame) < std::tie(b.camera, b.frame);
  });
  if (truth_masks > 0 && score.missing == truth_masks) {
    Log().warn("score: none of the {} truth masks in {} has a silhouette in {} (<camera>/<frame>.png)", truth_masks,
               masks.string(), silhouettes.string());
  }
  return score;
}

SilhouetteSummary SilhouetteScore::All() const {
  std::vector<const SilhouetteCounts*> all;
  for (const SilhouetteCounts& c : frames) all.push_back(&c);
  return Summarise(all);
}

std::map<std::string, SilhouetteSummary> SilhouetteScore::ByCamera() const {
  std::map<std::string, std::vector<const SilhouetteCounts*>> by_camera;
  for (const SilhouetteCounts& c : frames) by_camera[c.camera].push_back(&c);
  std::map<std::string, SilhouetteSummary> out;
  for (const auto& [camera, list] : by_camera) out[camera] = Summarise(list);
  return out;
}

nlohmann::json SilhouetteScore::ToJson() const {
  Json j = SummaryJson(All());
  j["folder"] = fs::absolute(silhouettes).lexically_normal().string();
  j["missing"] = missing;
  j["empty_camera_frames"] = empty_frames;
  j["empty_false_pixels"] = empty_false;
  j["cameras"] = Json::object();
  for (const auto& [camera, s] : ByCamera()) j["cameras"][camera] = SummaryJson(s);
  return j;
}

std::string SilhouetteScore::Markdown() const {
  std::ostringstream out;
  out << "**Silhouettes against the truth masks** (camera-frames with the person in the truth mask; false "
         "foreground and missed body pixels as a share of the true body's; near the outline: the share of those "
         "errors within one pixel of the true outline)\n\n"
      << "| Camera | Frames | IoU median | IoU p10 | False | Missed | Near the outline |\n"
      << "|---|---|---|---|---|---|---|\n";
  for (const auto& [camera, s] : ByCamera()) out << SummaryRow(camera, s);
  out << SummaryRow("All", All());
  if (empty_frames) {
    out << "\n" << empty_frames << " camera-frames without the person in view: " << empty_false
        << " silhouette pixels there.\n";
  }
  if (missing) out << "\n" << missing << " camera-frames have a truth mask but no silhouette.\n";
  return out.str();
}

std::string SilhouetteScore::Csv() const {
  std::ostringstream out;
  out << "camera,frame,truth_px,silhouette_px,iou,false_near_px,false_far_px,missed_near_px,missed_far_px\n";
  for (const SilhouetteCounts& c : frames) {
    out << c.camera << "," << c.frame << "," << c.truth << "," << c.silhouette << "," << Fixed(c.iou(), 6) << ","
        << c.false_near << "," << c.false_far << "," << c.missed_near << "," << c.missed_far << "\n";
  }
  return out.str();
}

}  // namespace irbench
