#include "ci/score/score.h"

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <tuple>
#include <fstream>
#include <sstream>

#include "common/error.h"
#include "sequence_format/frame_lines.h"

namespace irbench {
namespace fs = std::filesystem;
namespace {

using Json = nlohmann::json;

// A point [x, y, z]; nullopt for null or absent; InputError otherwise.
std::optional<Eigen::Vector3d> Point(const Json& parent, const std::string& key, const fs::path& file,
                                     const Json& line) {
  if (!parent.is_object() || !parent.contains(key) || parent[key].is_null()) return std::nullopt;
  const Json& v = parent[key];
  if (!v.is_array() || v.size() != 3 || !v[0].is_number() || !v[1].is_number() || !v[2].is_number()) {
    throw InputError(file.string(), "line " + std::to_string(line["_line"].get<int>()) + ": " + key,
                     "expected [x, y, z] in metres");
  }
  return Eigen::Vector3d(v[0].get<double>(), v[1].get<double>(), v[2].get<double>());
}

std::string LineField(const Json& line, const std::string& key) {
  return "line " + std::to_string(line.value("_line", 0)) + ": " + key;
}

// A boolean field: nullopt when absent or null; InputError for another type.
std::optional<bool> Flag(const Json& parent, const std::string& key, const fs::path& file,
                         const Json& line) {
  if (!parent.is_object() || !parent.contains(key) || parent[key].is_null()) return std::nullopt;
  if (!parent[key].is_boolean()) throw InputError(file.string(), LineField(line, key), "expected true, false or null");
  return parent[key].get<bool>();
}
std::optional<bool> Flag(const Json& line, const std::string& key, const fs::path& file) {
  return Flag(line, key, file, line);
}

// "tracking" (also when absent), "partial" (someone partly in view, not
// scored) or "empty"; InputError otherwise.
std::string TrackState(const Json& line, const fs::path& file) {
  if (!line.contains("state")) return "tracking";
  const Json& s = line["state"];
  if (!s.is_string() || (s != "tracking" && s != "empty" && s != "partial")) {
    throw InputError(file.string(), LineField(line, "state"), "expected \"tracking\", \"partial\" or \"empty\"");
  }
  return s;
}

}  // namespace

std::vector<std::string> ConfusionLabels(const std::map<std::string, std::map<std::string, int>>& confusion) {
  std::vector<std::string> labels;
  for (const auto& [t, row] : confusion) {
    labels.push_back(t);
    for (const auto& [l, n] : row) labels.push_back(l);
  }
  std::sort(labels.begin(), labels.end());
  labels.erase(std::unique(labels.begin(), labels.end()), labels.end());
  return labels;
}

const std::vector<std::string>& ThesisMotionLabels() {
  static const std::vector<std::string> labels = {"REST", "PAUSE",   "UP",       "DOWN", "LEFT",
                                                  "RIGHT", "FORWARD", "BACKWARD", "OTHER"};
  return labels;
}

double ThesisMotionRecall(const std::string& model, const std::string& label) {
  // The diagonals of Table 7.1 (CRF, mean 74.3 %) and Table 7.2 (LDCRF, mean 85.5 %).
  static const double crf[] = {0.962, 0.858, 0.745, 0.708, 0.633, 0.738, 0.778, 0.500, 0.767};
  static const double ldcrf[] = {0.9940, 0.8678, 0.7766, 0.8566, 0.8613, 0.8689, 0.6667, 0.9978, 0.8034};
  const std::vector<std::string>& labels = ThesisMotionLabels();
  if (model != "crf" && model != "ldcrf") return std::nan("");
  for (size_t i = 0; i < labels.size(); ++i) {
    if (labels[i] == label) return model == "crf" ? crf[i] : ldcrf[i];
  }
  return std::nan("");
}

std::map<std::string, double> PerLabelRecall(const std::map<std::string, std::map<std::string, int>>& confusion) {
  std::map<std::string, double> recall;
  for (const auto& [truth, row] : confusion) {
    int total = 0;
    for (const auto& [found, n] : row) total += n;
    const auto self = row.find(truth);
    if (total > 0) recall[truth] = double(self == row.end() ? 0 : self->second) / total;
  }
  return recall;
}

double MeanRecall(const std::map<std::string, std::map<std::string, int>>& confusion) {
  const std::map<std::string, double> recall = PerLabelRecall(confusion);
  double sum = 0;
  for (const auto& [label, r] : recall) sum += r;
  return recall.empty() ? std::nan("") : sum / recall.size();
}

std::string MotionConfusionMarkdown(const std::map<std::string, std::map<std::string, int>>& confusion) {
  std::vector<std::string> labels;
  const std::vector<std::string> present = ConfusionLabels(confusion);
  for (const std::string& l : ThesisMotionLabels()) {
    if (std::find(present.begin(), present.end(), l) != present.end()) labels.push_back(l);
  }
  for (const std::string& l : present) {
    if (std::find(labels.begin(), labels.end(), l) == labels.end()) labels.push_back(l);
  }
  std::ostringstream out;
  out << "| truth \\ found |";
  for (const std::string& l : labels) out << " " << l << " |";
  out << "\n|---|";
  for (size_t i = 0; i < labels.size(); ++i) out << "---:|";
  out << "\n";
  std::map<std::string, int> totals;
  for (const std::string& t : labels) {
    const auto row = confusion.find(t);
    if (row == confusion.end()) continue;
    int total = 0;
    for (const auto& [found, n] : row->second) total += n;
    totals[t] = total;
    out << "| " << t << " |";
    for (const std::string& l : labels) {
      const auto c = row->second.find(l);
      const int n = c == row->second.end() ? 0 : c->second;
      out << " " << (n ? Fixed(double(n) / total, 3) : std::string("")) << " |";
    }
    out << "\n";
  }
  const std::map<std::string, double> recall = PerLabelRecall(confusion);
  out << "\n| label | frames | recall | thesis CRF | thesis LDCRF |\n|---|---:|---:|---:|---:|\n";
  for (const std::string& l : labels) {
    const auto r = recall.find(l);
    if (r == recall.end()) continue;
    const double crf = ThesisMotionRecall("crf", l), ldcrf = ThesisMotionRecall("ldcrf", l);
    out << "| " << l << " | " << totals[l] << " | " << Fixed(100 * r->second, 1) << " % | "
        << (std::isnan(crf) ? "" : Fixed(100 * crf, 1) + " %") << " | "
        << (std::isnan(ldcrf) ? "" : Fixed(100 * ldcrf, 1) + " %") << " |\n";
  }
  out << "| **mean** | | **" << Fixed(100 * MeanRecall(confusion), 1) << " %** | 74.3 % | 85.5 % |\n";
  return out.str();
}

namespace {

// "A1+A3": an unordered pair of atom names, in order.
std::string PairKey(const std::string& a, const std::string& b) { return a < b ? a + "+" + b : b + "+" + a; }

const Json* Child(const Json& j, const std::string& key) {
  return j.is_object() && j.contains(key) && !j[key].is_null() ? &j[key] : nullptr;
}

}  // namespace

std::string Fixed(double v, int digits) {
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%.*f", digits, v);
  return buf;
}

std::string TitleCase(const std::string& joint) {
  std::string out;
  bool up = true;
  for (char c : joint) {
    if (c == '_') {
      out += ' ';
      up = true;
    } else {
      out += up ? static_cast<char>(std::toupper(static_cast<unsigned char>(c))) : c;
      up = false;
    }
  }
  return out;
}

std::vector<bool> ChauvenetOutliers(const std::vector<double>& samples) {
  const size_t n = samples.size();
  std::vector<bool> out(n, false);
  if (n < 3) return out;
  double mean = 0;
  for (double x : samples) mean += x / n;
  double var = 0;
  for (double x : samples) var += (x - mean) * (x - mean) / n;
  const double sd = std::sqrt(var);
  if (!(sd > 0)) return out;
  for (size_t i = 0; i < n; ++i) {
    const double p = std::erfc(std::abs(samples[i] - mean) / (sd * std::sqrt(2.0)));
    out[i] = n * p < 0.5;
  }
  return out;
}

ErrorStats Summarise(const std::vector<double>& errors, int missing, std::vector<bool>* outliers) {
  ErrorStats s;
  s.total = static_cast<int>(errors.size());
  s.missing = missing;
  const std::vector<bool> outlier = ChauvenetOutliers(errors);
  if (outliers) *outliers = outlier;
  std::vector<double> kept;
  for (size_t i = 0; i < errors.size(); ++i) {
    if (outlier[i]) {
      ++s.outliers;
    } else {
      kept.push_back(errors[i]);
    }
  }
  if (kept.empty()) return s;
  for (double e : kept) s.mean += e / kept.size();
  for (double e : kept) {
    s.std += (e - s.mean) * (e - s.mean) / kept.size();
    s.max = std::max(s.max, e);
  }
  s.std = std::sqrt(s.std);
  return s;
}

const std::vector<std::string>& ScoredJoints() {
  static const std::vector<std::string> joints = {"root",           "waist",      "neck",
                                                  "left_shoulder",  "left_elbow", "left_wrist",
                                                  "right_shoulder", "right_elbow", "right_wrist"};
  return joints;
}

namespace {

// Postures (thesis 5.1): the truth's pair against the track's, unordered,
// whenever the hull gave the tracker one.
void ScorePosture(const Json* truth_labels, const Json* track, Score* score) {
  const Json* truth_posture = truth_labels ? Child(*truth_labels, "posture") : nullptr;
  if (!truth_posture || !truth_posture->is_array() || truth_posture->size() != 2 || !(*truth_posture)[0].is_string() ||
      !(*truth_posture)[1].is_string()) {
    return;
  }
  const std::string truth_pair = PairKey((*truth_posture)[0], (*truth_posture)[1]);
  const Json* track_posture = track ? Child(*track, "posture") : nullptr;
  const Json* pair = track_posture && track_posture->is_object() ? Child(*track_posture, "pair") : nullptr;
  if (!pair || !pair->is_array() || pair->size() != 2 || !(*pair)[0].is_string() || !(*pair)[1].is_string()) {
    ++score->posture.missing;
    return;
  }
  const std::string tracked_pair = PairKey((*pair)[0], (*pair)[1]);
  ++score->posture_confusion[truth_pair][tracked_pair];
  ++score->posture.total;
  score->posture.correct += tracked_pair == truth_pair;
}

// Gestures (thesis 5.3): the truth's runs of one gesture label, each
// identified as the last label the track reports within it.
struct GestureRuns {
  Score* score = nullptr;
  std::string gesture{}, label{};  // the current run's truth and latest tracked label

  void Add(int frame, const Json* truth_labels, const Json* track) {
    const Json* truth_gesture = truth_labels ? Child(*truth_labels, "gesture") : nullptr;
    const std::string truth = truth_gesture && truth_gesture->is_string() ? truth_gesture->get<std::string>() : "";
    if (truth != gesture) {
      Close();
      gesture = truth;
    }
    const Json* track_gesture = track ? Child(*track, "gesture") : nullptr;
    const Json* found = track_gesture && track_gesture->is_object() ? Child(*track_gesture, "label") : nullptr;
    if (!gesture.empty() && found && found->is_string()) label = found->get<std::string>();
    score->gesture_timeline.emplace_back(frame, truth, found && found->is_string() ? found->get<std::string>() : "");
  }
  void Close() {
    if (!gesture.empty()) {
      const std::string found = label.empty() ? "(none)" : label;
      ++score->gesture_confusion[gesture][found];
      ++score->gesture.total;
      score->gesture.correct += found == gesture;
    }
    label.clear();
  }
};

}  // namespace

Score ScoreTrack(const fs::path& truth_jsonl, const fs::path& track_jsonl, const ScoreOptions& options) {
  std::map<int, Json> truth_by_frame, track_by_frame;
  const std::vector<Json> truth_lines = ReadJsonLines(truth_jsonl, &truth_by_frame);
  ReadJsonLines(track_jsonl, &track_by_frame);
  Score score;
  score.truth_frames = static_cast<int>(truth_lines.size());
  std::map<std::string, std::vector<double>> joint_errors, pointing_errors;
  std::map<std::string, std::vector<int>> joint_frames, pointing_frames;
  std::map<std::string, int> joint_missing, pointing_missing;
  GestureRuns gestures{.score = &score};
  for (const auto& [frame, truth] : truth_by_frame) {
    if (!Flag(truth, "present", truth_jsonl).value_or(false)) continue;
    ++score.present_frames;
    const auto it = track_by_frame.find(frame);
    const Json* track = it == track_by_frame.end() ? nullptr : &it->second;
    const bool tracking = track && TrackState(*track, track_jsonl) == "tracking";
    score.tracked_frames += tracking;
    const Json* truth_joints = Child(truth, "joints3d");
    const Json* track_joints = tracking ? Child(*track, "joints3d") : nullptr;
    const Json* truth_labels_node = Child(truth, "labels");
    const Json* truth_rest = truth_labels_node ? Child(*truth_labels_node, "rest") : nullptr;
    for (const std::string& joint : ScoredJoints()) {
      const auto t = truth_joints ? Point(*truth_joints, joint, truth_jsonl, truth) : std::nullopt;
      if (!t) continue;
      // Thesis 6.6: joints of an arm at rest in the truth are not scored.
      if (!options.include_rest_arms && truth_rest && (joint.find("elbow") != std::string::npos ||
                                                       joint.find("wrist") != std::string::npos)) {
        const std::string side = joint.rfind("left", 0) == 0 ? "left" : "right";
        if (Flag(*truth_rest, side, truth_jsonl, truth).value_or(false)) continue;
      }
      const auto p = track_joints ? Point(*track_joints, joint, track_jsonl, *track) : std::nullopt;
      if (!p) {
        ++joint_missing[joint];
        continue;
      }
      joint_errors[joint].push_back(100.0 * (*p - *t).norm());
      joint_frames[joint].push_back(frame);
    }
    // Pointing: where the truth has a pointing ray for that hand.
    const Json* truth_pointing = Child(truth, "pointing");
    const Json* track_pointing = tracking ? Child(*track, "pointing") : nullptr;
    for (const std::string side : {"right", "left"}) {
      const Json* tp = truth_pointing ? Child(*truth_pointing, side) : nullptr;
      if (!tp) continue;
      const auto truth_dir = Point(*tp, "dir", truth_jsonl, truth);
      if (!truth_dir) continue;
      const Json* kp = track_pointing ? Child(*track_pointing, side) : nullptr;
      const auto dir = kp ? Point(*kp, "dir", track_jsonl, *track) : std::nullopt;
      if (!dir || dir->norm() == 0) {
        ++pointing_missing[side];
        continue;
      }
      const double c = std::clamp(dir->normalized().dot(truth_dir->normalized()), -1.0, 1.0);
      // atan2 keeps small angles exact where acos loses them.
      const double angle = std::atan2(dir->normalized().cross(truth_dir->normalized()).norm(), c);
      pointing_errors[side].push_back(angle * 180.0 / M_PI);
      pointing_frames[side].push_back(frame);
    }
    // Rest state per arm.
    const Json* track_rest = tracking ? Child(*track, "rest") : nullptr;
    for (const std::string side : {"right", "left"}) {
      if (!truth_rest || !truth_rest->contains(side) || !(*truth_rest)[side].is_boolean()) continue;
      const bool truth_value = (*truth_rest)[side];
      if (!track_rest || !track_rest->contains(side) || !(*track_rest)[side].is_boolean()) {
        ++score.rest[side].missing;
        ++score.rest["both"].missing;
        continue;
      }
      const bool ok = (*track_rest)[side].get<bool>() == truth_value;
      for (const std::string& key : {side, std::string("both")}) {
        ++score.rest[key].total;
        score.rest[key].correct += ok;
      }
    }
    // Motion labels per arm.
    const Json* truth_labels = Child(truth, "labels");
    const Json* truth_motion = truth_labels ? Child(*truth_labels, "motion") : nullptr;
    const Json* track_motion = tracking ? Child(*track, "motion") : nullptr;
    for (const std::string side : {"right", "left"}) {
      if (!truth_motion || !truth_motion->contains(side) || !(*truth_motion)[side].is_string()) continue;
      const std::string truth_label = (*truth_motion)[side];
      if (!track_motion || !track_motion->contains(side) || !(*track_motion)[side].is_string()) {
        ++score.motion.missing;
        score.motion_timeline[side].emplace_back(frame, truth_label, "");
        continue;
      }
      const std::string label = (*track_motion)[side];
      score.motion_timeline[side].emplace_back(frame, truth_label, label);
      ++score.motion_confusion[truth_label][label];
      ++score.motion.total;
      score.motion.correct += label == truth_label;
    }
    gestures.Add(frame, truth_labels, track);
    ScorePosture(truth_labels, track, &score);
  }
  gestures.Close();
  // One Chauvenet pass per series gives both the summary and the per-frame flags.
  auto summarise = [](const std::vector<double>& errors, const std::vector<int>& frames, int missing,
                      ErrorStats* stats, std::vector<std::tuple<int, double, bool>>* rows) {
    std::vector<bool> out;
    *stats = Summarise(errors, missing, &out);
    for (size_t i = 0; i < errors.size(); ++i) rows->emplace_back(frames[i], errors[i], out[i]);
  };
  for (const std::string& joint : ScoredJoints()) {
    summarise(joint_errors[joint], joint_frames[joint], joint_missing[joint], &score.joints[joint],
              &score.joint_errors[joint]);
  }
  for (const std::string side : {"right", "left"}) {
    summarise(pointing_errors[side], pointing_frames[side], pointing_missing[side], &score.pointing[side],
              &score.pointing_errors[side]);
  }
  return score;
}

namespace {

// A confusion matrix (truth -> found -> count) as a Markdown table, rows
// truth, columns found, over the labels either side uses.
std::string ConfusionMarkdown(const std::map<std::string, std::map<std::string, int>>& confusion) {
  const std::vector<std::string> labels = ConfusionLabels(confusion);
  std::ostringstream out;
  out << "| |";
  for (const std::string& l : labels) out << " " << l << " |";
  out << "\n|---|";
  for (size_t i = 0; i < labels.size(); ++i) out << "---|";
  out << "\n";
  for (const std::string& t : labels) {
    const auto row = confusion.find(t);
    if (row == confusion.end()) continue;
    out << "| " << t << " |";
    for (const std::string& l : labels) {
      const auto c = row->second.find(l);
      out << " " << (c == row->second.end() ? 0 : c->second) << " |";
    }
    out << "\n";
  }
  return out.str();
}

}  // namespace

nlohmann::json Score::ToJson() const {
  auto stats = [](const ErrorStats& s) {
    // Nothing scored: null, never a perfect 0.
    const auto value = [&](double v) { return s.total ? Json(v) : Json(nullptr); };
    return Json{{"mean", value(s.mean)}, {"std", value(s.std)}, {"outliers", s.outliers}, {"total", s.total},
                {"missing", s.missing}, {"max", value(s.max)}};
  };
  Json j;
  j["format"] = "irbench.score/1";
  j["frames"] = {{"truth", truth_frames}, {"present", present_frames}, {"tracked", tracked_frames}};
  j["joints_cm"] = Json::object();
  for (const auto& [name, s] : joints) j["joints_cm"][name] = stats(s);
  j["pointing_deg"] = Json::object();
  for (const auto& [side, s] : pointing) j["pointing_deg"][side] = stats(s);
  j["rest"] = Json::object();
  for (const auto& [side, a] : rest) {
    j["rest"][side] = {{"accuracy", a.total ? Json(a.rate()) : Json(nullptr)},
                       {"correct", a.correct}, {"total", a.total}, {"missing", a.missing}};
  }
  Json recall = Json::object();
  for (const auto& [label, r] : PerLabelRecall(motion_confusion)) recall[label] = r;
  j["motion_labels"] = {{"accuracy", motion.total ? Json(motion.rate()) : Json(nullptr)},
                        {"mean_recall", motion.total ? Json(MeanRecall(motion_confusion)) : Json(nullptr)},
                        {"recall", recall},
                        {"total", motion.total},
                        {"missing", motion.missing},
                        {"confusion", motion_confusion}};
  j["postures"] = {{"accuracy", posture.total ? Json(posture.rate()) : Json(nullptr)},
                   {"total", posture.total},
                   {"missing", posture.missing},
                   {"confusion", posture_confusion}};
  j["gestures"] = {{"identification", gesture.total ? Json(gesture.rate()) : Json(nullptr)},
                   {"performances", gesture.total},
                   {"confusion", gesture_confusion}};
  j["silhouettes"] = silhouettes ? silhouettes->ToJson() : Json(nullptr);
  return j;
}

std::string Score::Markdown() const {
  std::ostringstream out;
  out << "Frames: " << truth_frames << " in the truth, " << present_frames << " with the person on the stage, "
      << tracked_frames << " of those tracked.\n\n";
  out << "**Joint errors, cm** (thesis Table 6.1; outliers by Chauvenet's criterion)\n\n"
      << "| Joint | Mean | Std | Outliers | Total | Missing |\n|---|---|---|---|---|---|\n";
  for (const std::string& joint : ScoredJoints()) {
    const ErrorStats& s = joints.at(joint);
    out << "| " << TitleCase(joint) << " | " << (s.total ? Fixed(s.mean, 2) : "–") << " | "
        << (s.total ? Fixed(s.std, 2) : "–") << " | " << s.outliers << " | " << s.total << " | " << s.missing
        << " |\n";
  }
  out << "\n**Pointing errors, degrees** (thesis Table 6.3)\n\n"
      << "| Hand | Mean | Std | Outliers | Total | Missing |\n|---|---|---|---|---|---|\n";
  for (const std::string side : {"right", "left"}) {
    const ErrorStats& s = pointing.at(side);
    out << "| " << TitleCase(side) << " hand | " << (s.total ? Fixed(s.mean, 2) : "–") << " | "
        << (s.total ? Fixed(s.std, 2) : "–") << " | " << s.outliers << " | " << s.total << " | " << s.missing
        << " |\n";
  }
  out << "\n**Rest state** (thesis 6.4)\n\n| Arm | Accuracy | Frames | Missing |\n|---|---|---|---|\n";
  for (const std::string side : {"right", "left", "both"}) {
    const auto it = rest.find(side);
    const Accuracy a = it == rest.end() ? Accuracy{} : it->second;
    out << "| " << TitleCase(side) << " | " << (a.total ? Fixed(100 * a.rate(), 2) + "%" : "–") << " | " << a.total
        << " | " << a.missing << " |\n";
  }
  if (!motion_confusion.empty()) {
    out << "\n**Motion labels** (thesis Tables 7.1-7.2; rows truth, columns tracked, shares of the row; "
        << motion.total << " arm-frames, " << motion.missing << " without a label; accuracy "
        << Fixed(100 * motion.rate(), 2) << "%, mean per-label recall " << Fixed(100 * MeanRecall(motion_confusion), 2)
        << "%)\n\n"
        << MotionConfusionMarkdown(motion_confusion);
  }
  if (!posture_confusion.empty()) {
    out << "\n**Postures** (thesis 5.1: atom pairs, unordered; rows truth, columns recognised; "
        << Fixed(100 * posture.rate(), 2) << "% of " << posture.total << " frames right, " << posture.missing
        << " without a posture)\n\n"
        << ConfusionMarkdown(posture_confusion);
  }
  if (!gesture_confusion.empty()) {
    out << "\n**Gestures** (thesis 5.3: each performance the truth marks, identified as the last gesture the track "
           "reports in it; rows truth, columns identified; "
        << Fixed(100 * gesture.rate(), 2) << "% of " << gesture.total << " performances)\n\n"
        << ConfusionMarkdown(gesture_confusion);
  }
  if (silhouettes) out << "\n" << silhouettes->Markdown();
  return out.str();
}

}  // namespace irbench
