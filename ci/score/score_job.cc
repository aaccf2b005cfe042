#include "ci/score/score_job.h"

#include <sstream>

#include "ci/report/report.h"
#include "ci/score/score.h"
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

}  // namespace

fs::path RunScoreJob(const ScoreJobOptions& options, std::string* summary, Score* score_out) {
  const fs::path truth = options.sequence / "truth" / "frames.jsonl";
  if (!fs::is_directory(options.sequence)) throw InputError(options.sequence.string(), "", "no such sequence folder");
  if (!fs::is_regular_file(truth)) throw InputError(truth.string(), "", "missing: the sequence has no truth");
  const fs::path track = options.track.empty() ? options.sequence / "track" / "track.jsonl" : options.track;
  if (!fs::is_regular_file(track)) {
    throw InputError(track.string(), "--track", "no such track file (irbench track writes one; or give --track)");
  }
  Score score = ScoreTrack(truth, track, options.score);
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
  const fs::path out = options.out.empty() ? options.sequence / "score" : options.out;
  StagingDir staging(out, options.overwrite, "--out");
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
