// The recognition half closed loop, in miniature (the full tables are the
// `gestures` suite's and docs/recognition.md's): two persons perform two
// gestures twice each; the gesture models are trained on one person's
// tracked session and recognise the other's, online in `irbench track` and in
// batch (Table 5.2's protocol); postures are scored against the truth. Each
// session is tracked once and the trainings reuse the tracks.
// Motion labels (thesis 7.1): the shipped LDCRF (trained on other persons)
// labels the test person's arms in `irbench track`; and models trained here
// on the one person label the other exactly as `irbench track` with them
// does (the training's tables are the tracker's output, scored).

#include <gtest/gtest.h>

#include <filesystem>

#include "ci/score/score.h"
#include "ci/train/gesture_training.h"
#include "ci/train/motion_label_training.h"
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

// The mean recall of the labels the truth gives at least 50 arm-frames (in
// this miniature FORWARD and BACKWARD have a handful: their recall is noise).
double CommonLabelRecall(const std::map<std::string, std::map<std::string, int>>& confusion) {
  std::map<std::string, std::map<std::string, int>> common;
  for (const auto& [truth, row] : confusion) {
    int n = 0;
    for (const auto& [found, count] : row) n += count;
    if (n >= 50) common[truth] = row;
  }
  EXPECT_GE(common.size(), 4u);
  return MeanRecall(common);
}

// Motion-label models trained on `train`'s tracked session label `test`
// (tracked already, in test/track):
// the training's tables are what `irbench track` with the models writes,
// scored.
void CheckMotionLabelsTrainedHere(const fs::path& dir, const fs::path& train, const fs::path& test) {
  MotionLabelTrainingJob job;
  job.train = {train};
  job.test = {test};
  job.out_dir = dir / "models";
  job.options.max_iterations = 60;
  const MotionLabelTrainingResult r = RunMotionLabelTraining(job);
  ASSERT_EQ(r.models.size(), 2u);
  EXPECT_GT(r.train_frames, 400);
  std::cout << r.evaluation.Markdown();
  EXPECT_GE(CommonLabelRecall(r.evaluation.confusion.at("crf")), 0.6);
  EXPECT_GE(CommonLabelRecall(r.evaluation.confusion.at("ldcrf")), 0.6);
  {
    const char* kind = "ldcrf";
    const auto& confusion = r.evaluation.confusion.at(kind);
    // `irbench track` with the model, scored: the same labels on every
    // tracked frame (the training labelled with the tracker's own labeller).
    TrackJobOptions track;
    track.sequence = test;
    track.tracker.motion_model = std::string(kind) == "crf" ? MotionModelChoice::kCrf : MotionModelChoice::kLdcrf;
    track.tracker.motion_labels = dir / "models" / (std::string("motion_") + kind + ".json");
    track.out = dir / (std::string("track_") + kind);
    RunTrackJob(track);
    const Score score = ScoreTrack(test / "truth/frames.jsonl", track.out / "track.jsonl");
    int compared = 0;
    for (const auto& [truth, row] : confusion) {
      for (const auto& [found, n] : row) {
        if (found == "none") continue;
        const auto t = score.motion_confusion.find(truth);
        EXPECT_EQ(t == score.motion_confusion.end() || !t->second.count(found) ? 0 : t->second.at(found), n)
            << kind << " " << truth << " -> " << found;
        compared += n;
      }
    }
    EXPECT_EQ(compared, score.motion.total) << kind;
  }
}

TEST(RecognitionClosedLoop, GesturesPosturesAndMotionLabelsAcrossPersons) {
  if (!fs::exists(DefaultPostureAtomsPath())) GTEST_SKIP() << "no shipped posture atoms";
  const fs::path dir = testing::FreshTempDir("recognition");
  testing::WriteText(dir / "session.json", kSession);
  // p3 is a test person of every shipped model (docs/recognition.md).
  const fs::path train = Render(dir, "p1"), test = Render(dir, "p3");
  // Each session is tracked once, as a user would (`irbench track SEQ`):
  // both trainings read the tracks from SEQ/track.
  TrackJobOptions track;
  track.sequence = train;
  track.out = train / "track";
  RunTrackJob(track);

  GestureTrainingJob job;
  job.train = {train};
  job.out = dir / "gestures.json";
  job.options.restarts = 2;
  const GestureTrainingResult first = RunGestureTraining(job);
  EXPECT_EQ(first.segments, 4);
  EXPECT_EQ(first.tracks.at("p1"), "track/");

  // Online, in irbench track, then scored as a user would.
  track.sequence = test;
  track.tracker.gesture_models = job.out;
  track.out = test / "track";
  RunTrackJob(track);
  const Score score = ScoreTrack(test / "truth/frames.jsonl", track.out / "track.jsonl");
  EXPECT_EQ(score.gesture.total, 4);
  EXPECT_GE(score.gesture.correct, 3) << score.Markdown();

  // Table 5.2's protocol: each of the test person's four performances put to
  // both gestures' models, trained again from the same track (the same
  // models, byte for byte).
  job.test = {test};
  job.out = dir / "gestures_again.json";
  const GestureTrainingResult r = RunGestureTraining(job);
  EXPECT_EQ(r.tracks.at("p1"), "track/");
  EXPECT_EQ(r.tracks.at("p3"), "track/");
  EXPECT_EQ(testing::ReadText(job.out), testing::ReadText(dir / "gestures.json"));
  std::cout << r.evaluation.Markdown();
  for (const char* kind : {"fhmm", "pahmm", "hmm"}) {
    int right = 0, total = 0;
    for (const auto& [gesture, c] : r.evaluation.counts.at(kind).at("p3")) right += c.first, total += c.second;
    EXPECT_EQ(total, 4) << kind;
    if (std::string(kind) == "fhmm") {
      EXPECT_GE(right, 3) << kind;
    }
  }
  // Postures: the shipped atoms (trained on other persons) on this one.
  EXPECT_GT(score.posture.total, 400);
  EXPECT_GE(score.posture.rate(), 0.6) << score.Markdown();
  std::cout << "postures right on " << 100 * score.posture.rate() << "% of " << score.posture.total << " frames\n";
  // The pair agrees with the pose tracker's rest state (the shipped atoms'
  // pair_rest_state): the same atoms by their weights alone do worse (in
  // this session of flaps and overhead raises, mostly transitions, 74.8 %
  // against 73.3 %; on the atom tours' holds 91.2 % against 86.5 %,
  // docs/recognition.md).
  PostureAtoms weights_alone = PostureAtoms::Load(DefaultPostureAtomsPath());
  if (weights_alone.pair_rest_state) {
    weights_alone.pair_rest_state = false;
    weights_alone.Save(dir / "atoms_weights_alone.json");
    TrackJobOptions alone = track;
    alone.tracker.posture_atoms = dir / "atoms_weights_alone.json";
    alone.out = test / "track_weights_alone";
    RunTrackJob(alone);
    const Score s = ScoreTrack(test / "truth/frames.jsonl", alone.out / "track.jsonl");
    EXPECT_EQ(s.posture.total, score.posture.total);
    EXPECT_GT(score.posture.rate(), s.posture.rate()) << s.Markdown();
    std::cout << "by the weights alone " << 100 * s.posture.rate() << "%\n";
  }
  // Motion labels from the shipped LDCRF: on nearly every tracked arm-frame.
  // Right on 79.5 % of them with the 200-particle tracker (2026-12-07; the
  // shipped model was trained on 100-particle tracks, and its mean
  // per-label recall here went 83.2 -> 84.0 %), so the guard is 78 %.
  if (fs::exists(DefaultMotionLabelModelPath(MotionModelKind::kLdcrf))) {
    EXPECT_GT(score.motion.total, 800);
    EXPECT_LT(score.motion.missing, score.motion.total / 10);
    EXPECT_GE(score.motion.rate(), 0.78) << score.Markdown();
    std::cout << "motion labels: right on " << 100 * score.motion.rate() << "% of " << score.motion.total
              << " arm-frames\n";
    EXPECT_GE(CommonLabelRecall(score.motion_confusion), 0.7) << score.Markdown();
    std::cout << "motion labels: mean per-label recall " << 100 * MeanRecall(score.motion_confusion) << "%\n";
  }
  CheckMotionLabelsTrainedHere(dir, train, test);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace irbench