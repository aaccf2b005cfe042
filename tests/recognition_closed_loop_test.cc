// The recognition half closed loop, in miniature (the full tables are the
// `gestures` suite's and docs/recognition.md's): two persons perform two
// gestures twice each; the gesture models are trained on one person's
// tracked session and recognise the other's, in batch (Table 5.2's protocol)
// and online in `irbench track`; postures are scored against the truth.

#include <gtest/gtest.h>

#include <filesystem>

#include "ci/score/score.h"
#include "ci/train/gesture_training.h"
#include "sim/sequence/render_job.h"
#include "tests/test_util.h"
#include "tracker/pipeline/track_job.h"
#include "tracker/posture/posture_atoms.h"

namespace irbench {
namespace {

namespace fs = std::filesystem;

// Two gestures that differ in both arms' atoms: both arms flap (A1/A4/A3),
// one arm goes overhead (A2).
constexpr char kSession[] = R"({"format": "irbench.session/1", "crossfade_s": 0.2, "items": [
  {"motion": "rest", "seconds": 0.6},
  {"motion": "flap_both", "cycles": 2}, {"motion": "rest", "seconds": 0.6},
  {"motion": "raise_overhead", "hold_s": 0.6}, {"motion": "rest", "seconds": 0.6},
  {"motion": "flap_both", "cycles": 2}, {"motion": "rest", "seconds": 0.6},
  {"motion": "raise_overhead", "hold_s": 0.6}, {"motion": "rest", "seconds": 0.6}]})";

fs::path Render(const fs::path& dir, const std::string& avatar) {
  RenderJobOptions options;
  options.rig = "theater4";
  options.avatar = avatar;
  options.motion = (dir / "session.json").string();
  options.sensor = "thesis";
  options.supersample = 1;
  options.out = dir / avatar;
  RunRenderJob(options);
  return options.out;
}

TEST(RecognitionClosedLoop, GesturesTrainedOnOnePersonAreRecognisedOnAnother) {
  if (!fs::exists(DefaultPostureAtomsPath())) GTEST_SKIP() << "no shipped posture atoms";
  const fs::path dir = testing::FreshTempDir("recognition");
  testing::WriteText(dir / "session.json", kSession);
  const fs::path train = Render(dir, "p1"), test = Render(dir, "p2");

  GestureTrainingJob job;
  job.train = {train};
  job.test = {test};
  job.out = dir / "gestures.json";
  job.options.restarts = 2;
  const GestureTrainingResult r = RunGestureTraining(job);
  EXPECT_EQ(r.segments, 4);
  std::cout << r.evaluation.Markdown();
  // Table 5.2's protocol: each of the test person's four performances put to
  // both gestures' models.
  for (const char* kind : {"fhmm", "pahmm", "hmm"}) {
    int right = 0, total = 0;
    for (const auto& [gesture, c] : r.evaluation.counts.at(kind).at("p2")) right += c.first, total += c.second;
    EXPECT_EQ(total, 4) << kind;
    if (std::string(kind) == "fhmm") {
      EXPECT_GE(right, 3) << kind;
    }
  }

  // Online, in irbench track, then scored as a user would.
  TrackJobOptions track;
  track.sequence = test;
  track.tracker.gesture_models = job.out;
  track.out = dir / "track";
  RunTrackJob(track);
  const Score score = ScoreTrack(test / "truth/frames.jsonl", track.out / "track.jsonl");
  EXPECT_EQ(score.gesture.total, 4);
  EXPECT_GE(score.gesture.correct, 3) << score.Markdown();
  // Postures: the shipped atoms (trained on other persons) on this one.
  EXPECT_GT(score.posture.total, 400);
  EXPECT_GE(score.posture.rate(), 0.6) << score.Markdown();
  std::cout << "postures right on " << 100 * score.posture.rate() << "% of " << score.posture.total << " frames\n";
  fs::remove_all(dir);
}

}  // namespace
}  // namespace irbench
