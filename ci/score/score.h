#pragma once
// Scoring tracker output against the truth in the thesis's shapes (thesis
// 6.6): per-joint 3D error mean, standard deviation, outliers by Chauvenet's
// criterion and total (Table 6.1); pointing angle error per hand (Table 6.3);
// rest-state accuracy (6.4); motion-label confusion per arm (Tables 7.1-7.2).
//
// Inputs: the sequence's truth/frames.jsonl and a track.jsonl (docs/formats.md,
// "Tracker output"), matched by frame index. Only frames where the truth says
// the person is `present` count. A value the tracker left null (or a frame it
// did not write, or wrote with state "empty") is "missing": counted, never
// scored as an error. As in the thesis, the elbow and wrist of an arm the truth
// labels at rest are left out of the joint errors (ScoreOptions).

#include <array>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <tuple>
#include <vector>

#include "ci/score/silhouette_score.h"

namespace irbench {

// Chauvenet's criterion, one pass: sample i is an outlier when
// n * erfc(|x_i - mean| / (std * sqrt 2)) < 0.5, mean and std (population) over
// all n samples. Returns one flag per sample; none when n < 3 or std is 0.
std::vector<bool> ChauvenetOutliers(const std::vector<double>& samples);

struct ErrorStats {
  double mean = 0, std = 0;  // over the samples that are not outliers
  int outliers = 0;          // removed by Chauvenet's criterion
  int total = 0;             // samples scored (outliers included), as the thesis's "Total"
  int missing = 0;           // frames where the truth has it and the track does not
  double max = 0;            // largest error kept
};

// Mean, std, outliers and total of `errors` (Chauvenet applied); the flags
// per sample go to `outliers` when given.
ErrorStats Summarise(const std::vector<double>& errors, int missing, std::vector<bool>* outliers = nullptr);

struct ScoreOptions {
  bool include_rest_arms = false;  // score elbows and wrists of arms at rest too
};

// "right_elbow" -> "Right Elbow": names as the tables print them.
std::string TitleCase(const std::string& name);

// `v` with `digits` decimals ("%.*f"), for the tables.
std::string Fixed(double v, int digits);

// The labels a confusion matrix (truth -> found -> count) uses on either
// side, sorted: its tables' rows and columns.
std::vector<std::string> ConfusionLabels(const std::map<std::string, std::map<std::string, int>>& confusion);

// Motion labels (thesis 7.1): the nine labels in the order of Tables 7.1 and
// 7.2, and each table's diagonal (the per-label recall the thesis measured)
// for model "crf" (Table 7.1) or "ldcrf" (Table 7.2); NaN for another.
const std::vector<std::string>& ThesisMotionLabels();
double ThesisMotionRecall(const std::string& model, const std::string& label);
// Per truth label, the share of its frames labelled as itself; and the mean
// of those over the labels the truth has.
std::map<std::string, double> PerLabelRecall(const std::map<std::string, std::map<std::string, int>>& confusion);
double MeanRecall(const std::map<std::string, std::map<std::string, int>>& confusion);
// A motion-label confusion matrix in the shape of Tables 7.1-7.2: rows truth,
// columns found, row shares, the thesis's labels first in its order; then
// per label the frames, our recall and the thesis's CRF and LDCRF recall,
// and the means.
std::string MotionConfusionMarkdown(const std::map<std::string, std::map<std::string, int>>& confusion);

// The nine joints of Table 6.1, in its order.
const std::vector<std::string>& ScoredJoints();

struct Score {
  int truth_frames = 0;    // lines in truth/frames.jsonl
  int present_frames = 0;  // of which the person is on the stage
  int tracked_frames = 0;  // present frames the track has with state "tracking"
  std::map<std::string, ErrorStats> joints;  // centimetres
  // Per-frame errors (cm) for plots: joint -> (frame, error, outlier).
  std::map<std::string, std::vector<std::tuple<int, double, bool>>> joint_errors;
  std::map<std::string, ErrorStats> pointing;  // "right", "left": degrees
  std::map<std::string, std::vector<std::tuple<int, double, bool>>> pointing_errors;
  // Rest state: agreement per arm and both.
  struct Accuracy {
    int correct = 0, total = 0, missing = 0;
    double rate() const { return total ? double(correct) / total : 0.0; }
  };
  std::map<std::string, Accuracy> rest;  // "right", "left", "both"
  // Motion labels: truth label -> tracked label -> count, both arms together.
  std::map<std::string, std::map<std::string, int>> motion_confusion;
  Accuracy motion;
  // Per arm ("right", "left"), per frame with a truth label: the truth's
  // label and the track's ("" for none), for the report's timelines.
  std::map<std::string, std::vector<std::tuple<int, std::string, std::string>>> motion_timeline;
  // Postures (thesis 5.1): the truth's [primary, secondary] atoms against the
  // tracker's recognised pair, as unordered pairs ("A1+A3", names in
  // order); truth pair -> recognised pair -> count.
  std::map<std::string, std::map<std::string, int>> posture_confusion;
  Accuracy posture;
  // Gestures (thesis 5.3): each run of frames the truth labels with one
  // gesture is one performance; it is identified when the last gesture the
  // track reports within it is that gesture ("(none)" when it reports none).
  // Truth gesture -> identified as -> count.
  std::map<std::string, std::map<std::string, int>> gesture_confusion;
  Accuracy gesture;
  // Per present frame: the truth's gesture and the track's ("" for none),
  // for the report's timeline.
  std::vector<std::tuple<int, std::string, std::string>> gesture_timeline;
  // The tracker's silhouettes against the truth masks, when the track folder
  // has them (irbench track writes silhouettes/ beside track.jsonl).
  std::optional<SilhouetteScore> silhouettes;

  nlohmann::json ToJson() const;
  // The tables as GitHub-flavoured Markdown.
  std::string Markdown() const;
};

// Reads both files and scores. Throws InputError naming the file and line for
// unreadable or malformed input (a truth or track line that is not JSON, a
// joint that is not three numbers, a frame index that is not an integer).
Score ScoreTrack(const std::filesystem::path& truth_jsonl, const std::filesystem::path& track_jsonl,
                 const ScoreOptions& options = {});

}  // namespace irbench
