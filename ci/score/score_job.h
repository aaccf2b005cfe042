#pragma once
// `irbench score` as a job: scores a track against its sequence's truth
// (ci/score/score.h) and writes the tables, CSVs and the HTML report
// (ci/report/report.h) into one output folder.

#include <filesystem>
#include <string>

#include "ci/score/score.h"

namespace irbench {

struct ScoreJobOptions {
  std::filesystem::path sequence;
  std::filesystem::path track;  // default: <sequence>/track/track.jsonl
  std::filesystem::path out;    // default: <sequence>/score
  bool overwrite = false;
  bool report = true;  // also report.html and plots/ (ci/report/report.h)
  ScoreOptions score;
};

// `irbench score`: writes score.json, tables.md, joints.csv (per-joint
// summary), errors.csv (per frame and joint/hand) and, unless told not to,
// report.html with plots/ into `out` (complete or not at all). Returns the
// folder; `summary` (if given) receives the Markdown and `score` (if given)
// the figures.
std::filesystem::path RunScoreJob(const ScoreJobOptions& options, std::string* summary = nullptr,
                                  Score* score = nullptr);

}  // namespace irbench
