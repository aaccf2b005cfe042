#include "ci/score/score_job.h"

#include <fstream>
#include <sstream>

#include "ci/report/report.h"
#include "ci/score/score.h"
#include "sequence_format/frame_lines.h"
#include "common/atomic_file.h"
#include "common/error.h"
#include "common/logging.h"

namespace irbench {
namespace fs = std::filesystem;
namespace {

// A CSV number, empty when nothing was scored.
std::string Csv(int total, double v) {
  if (total == 0) return "";
  std::ostringstream out;
  out << v;
  return out.str();
}

// The files and folders a score reads: the sequence's truth/, calib/,
// frames/ (the report's viewer), manifest.json, the track file and the
// silhouettes beside it.
std::vector<fs::path> ScoreInputs(const ScoreJobOptions& options, const fs::path& track) {
  std::vector<fs::path> inputs;
  for (const char* part : {"truth", "calib", "frames", "manifest.json"}) inputs.push_back(options.sequence / part);
  inputs.push_back(track);
  if (fs::is_directory(track.parent_path() / "silhouettes")) inputs.push_back(track.parent_path() / "silhouettes");
  return inputs;
}

// Refuses a truth without frames (an interrupted or truncated render);
// warns when it covers fewer frames than the manifest says or the track has.
void CheckTruthCoverage(const ScoreJobOptions& options, const fs::path& truth, const fs::path& track,
                        const Score& score) {
  if (score.truth_frames == 0) {
    throw InputError(truth.string(), "", "no frames: nothing to score against (an interrupted or truncated render?)");
  }
  std::ifstream manifest_file(options.sequence / "manifest.json");
  const nlohmann::json manifest = nlohmann::json::parse(manifest_file, nullptr, false);
  if (!manifest.is_discarded() && manifest.is_object() && manifest.contains("frame_count") &&
      manifest["frame_count"].is_number_integer() && manifest["frame_count"].get<int>() > score.truth_frames) {
    Log().warn("score: {} holds {} of the {} frames the manifest lists; the rest are not scored", truth.string(),
               score.truth_frames, manifest["frame_count"].get<int>());
  }
  const std::map<int, nlohmann::json> track_lines = ReadFrameLines(track);
  if (!track_lines.empty() && track_lines.rbegin()->first >= score.truth_frames) {
    Log().warn("score: {} has frames up to {}, past the {} of {}: those are not scored", track.string(),
               track_lines.rbegin()->first, score.truth_frames, truth.string());
  }
}

}  // namespace

fs::path RunScoreJob(const ScoreJobOptions& options, std::string* summary, Score* score_out) {
  const fs::path truth = options.sequence / "truth" / "frames.jsonl";
  if (!fs::is_directory(options.sequence)) throw InputError(options.sequence.string(), "", "no such sequence folder");
  if (!fs::is_regular_file(truth)) throw InputError(truth.string(), "", "missing: the sequence has no truth");
  const fs::path track = options.track.empty() ? options.sequence / "track" / "track.jsonl" : options.track;
  if (!fs::is_regular_file(track)) {
    throw InputError(track.string(), "--track", "no such track file (irbench track writes one; or give --track)");
  }
  const fs::path out = options.out.empty() ? options.sequence / "score" : options.out;
  CheckOutputApart(out, ScoreInputs(options, track), "--out");
  CheckOutputReplaceable(out, options.overwrite, "--out");
  Score score = ScoreTrack(truth, track, options.score);
  CheckTruthCoverage(options, truth, track, score);
  // The silhouettes irbench track writes beside its track file, against the
  // truth masks.
  const fs::path silhouettes = track.parent_path() / "silhouettes";
  const fs::path masks = options.sequence / "truth" / "masks";
  if (fs::is_directory(silhouettes)) {
    if (fs::is_directory(masks)) {
      score.silhouettes = ScoreSilhouettes(masks, silhouettes);
    } else {
      Log().warn("score: {} has no truth masks: the silhouettes in {} are not scored", options.sequence.string(),
                 silhouettes.string());
    }
  }
  StagingDir staging(out, options.overwrite, "--out", "score");
  nlohmann::json j = score.ToJson();
  j["truth"] = fs::absolute(truth).lexically_normal().string();
  j["track"] = fs::absolute(track).lexically_normal().string();
  AtomicWriteFile(staging.path() / "score.json", j.dump(2) + "\n");
  const std::string md = score.Markdown();
  AtomicWriteFile(staging.path() / "tables.md", md);
  std::ostringstream joints_csv;
  joints_csv << "joint,mean_cm,std_cm,outliers,total,missing,max_cm\n";
  for (const std::string& joint : ScoredJoints()) {
    const ErrorStats& s = score.joints.at(joint);
    joints_csv << joint << "," << Csv(s.total, s.mean) << "," << Csv(s.total, s.std) << "," << s.outliers << ","
               << s.total << "," << s.missing << "," << Csv(s.total, s.max) << "\n";
  }
  for (const std::string side : {"right", "left"}) {
    const ErrorStats& s = score.pointing.at(side);
    joints_csv << "pointing_" << side << "_deg," << Csv(s.total, s.mean) << "," << Csv(s.total, s.std) << ","
               << s.outliers << "," << s.total << "," << s.missing << "," << Csv(s.total, s.max) << "\n";
  }
  AtomicWriteFile(staging.path() / "joints.csv", joints_csv.str());
  std::ostringstream errors_csv;
  errors_csv << "frame,what,error,unit,outlier\n";
  for (const auto& [joint, rows] : score.joint_errors) {
    for (const auto& [frame, e, outlier] : rows) errors_csv << frame << "," << joint << "," << e << ",cm," << outlier << "\n";
  }
  for (const auto& [side, rows] : score.pointing_errors) {
    for (const auto& [frame, e, outlier] : rows) {
      errors_csv << frame << ",pointing_" << side << "," << e << ",deg," << outlier << "\n";
    }
  }
  AtomicWriteFile(staging.path() / "errors.csv", errors_csv.str());
  if (score.silhouettes) AtomicWriteFile(staging.path() / "silhouettes.csv", score.silhouettes->Csv());
  if (options.report) {
    ReportOptions report;
    report.sequence = options.sequence;
    report.track = track;
    report.final_dir = staging.final_path();
    WriteReport(score, report, staging.path());
  }
  staging.Commit();
  if (summary) *summary = md;
  if (score_out) *score_out = score;
  return staging.final_path();
}

}  // namespace irbench
