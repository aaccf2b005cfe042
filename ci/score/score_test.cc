// The scorer on track files made from a rendered sequence's truth with known
// perturbations: it must report exactly those figures, and Chauvenet's
// criterion must remove exactly the injected outliers.

#include "ci/score/score.h"
#include "ci/score/score_job.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <Eigen/Geometry>
#include <cmath>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <random>

#include "common/error.h"
#include "sim/sequence/render_job.h"
#include "tests/render_session.h"
#include "tests/test_util.h"

namespace irbench {
namespace {
namespace fs = std::filesystem;
using Json = nlohmann::json;

TEST(ChauvenetTest, RemovesOnlyTheFarSamples) {
  std::vector<double> x(100, 3.0);
  x[7] = 40, x[50] = 35;
  const auto out = ChauvenetOutliers(x);
  for (size_t i = 0; i < x.size(); ++i) EXPECT_EQ(out[i], i == 7 || i == 50) << i;
  // A normal sample of 1000: the criterion expects to flag about
  // n * P(|z| > z_c) with n erfc(z_c / sqrt 2) = 0.5, i.e. half a sample.
  std::mt19937 rng(4);
  std::normal_distribution<double> normal(5, 2);
  std::vector<double> y(1000);
  for (double& v : y) v = normal(rng);
  int flagged = 0;
  for (bool b : ChauvenetOutliers(y)) flagged += b;
  EXPECT_LE(flagged, 3);
  EXPECT_TRUE(ChauvenetOutliers({1, 1, 1}) == std::vector<bool>(3, false));  // std 0
  const ErrorStats s = Summarise(x, 4);
  EXPECT_EQ(s.outliers, 2);
  EXPECT_EQ(s.total, 100);
  EXPECT_EQ(s.missing, 4);
  EXPECT_NEAR(s.mean, 3.0, 1e-12);
  EXPECT_NEAR(s.std, 0.0, 1e-6);
}

// Per-label recall by hand; the thesis's diagonals give its stated means
// (74.3 % CRF, 85.5 % LDCRF).
TEST(MotionLabelTablesTest, RecallAndTheThesisDiagonals) {
  const std::map<std::string, std::map<std::string, int>> c = {
      {"REST", {{"REST", 9}, {"PAUSE", 1}}}, {"UP", {{"UP", 1}, {"OTHER", 3}}}, {"LEFT", {{"none", 2}}}};
  const auto r = PerLabelRecall(c);
  EXPECT_DOUBLE_EQ(r.at("REST"), 0.9);
  EXPECT_DOUBLE_EQ(r.at("UP"), 0.25);
  EXPECT_DOUBLE_EQ(r.at("LEFT"), 0.0);
  EXPECT_EQ(r.count("PAUSE"), 0u);  // not a truth label here
  EXPECT_DOUBLE_EQ(MeanRecall(c), (0.9 + 0.25 + 0.0) / 3);
  double crf = 0, ldcrf = 0;
  for (const std::string& l : ThesisMotionLabels()) {
    crf += ThesisMotionRecall("crf", l);
    ldcrf += ThesisMotionRecall("ldcrf", l);
  }
  EXPECT_NEAR(100 * crf / 9, 74.3, 0.05);
  EXPECT_NEAR(100 * ldcrf / 9, 85.5, 0.05);
  EXPECT_TRUE(std::isnan(ThesisMotionRecall("hmm", "REST")));
  const std::string md = MotionConfusionMarkdown(c);
  // Rows in the thesis's order (REST before UP before LEFT), shares of the row.
  EXPECT_LT(md.find("\n| REST | 0.900 |"), md.find("\n| UP |"));
  EXPECT_LT(md.find("\n| UP |"), md.find("\n| LEFT |"));
  EXPECT_NE(md.find("| UP | 4 | 25.0 % | 74.5 % | 77.7 % |"), std::string::npos) << md;
}

class ScoreTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    // ctest runs each test in its own process, maybe at once: a folder per process.
    dir_ = irbench::testing::FreshTempDir("score_" + std::to_string(::getpid()));
    truth_ = irbench::testing::RenderSession(dir_, R"([
      {"motion": "point", "target": "helicopter", "side": "right", "hold_s": 0.8},
      {"motion": "raise_overhead", "side": "left", "hold_s": 0.3}])");
  }
  // A track line that says exactly what the truth says.
  static Json Perfect(const Json& t) {
    Json j = {{"frame", t["frame"]}, {"state", "tracking"}, {"joints3d", t["joints3d"]}};
    j["pointing"] = Json::object();
    for (const char* side : {"right", "left"}) {
      j["pointing"][side] = t["pointing"][side].is_null() ? Json(nullptr) : Json{{"dir", t["pointing"][side]["dir"]}};
    }
    j["rest"] = t["labels"]["rest"];
    j["motion"] = t["labels"]["motion"];
    return j;
  }
  static void Write(const fs::path& path, const std::vector<Json>& lines) {
    std::ofstream out(path);
    for (const Json& j : lines) out << j.dump() << "\n";
  }
  static void TearDownTestSuite() { fs::remove_all(dir_); }
  static fs::path dir_;
  static std::vector<Json> truth_;
};
fs::path ScoreTest::dir_;
std::vector<Json> ScoreTest::truth_;

TEST_F(ScoreTest, PerfectTrackScoresZero) {
  std::vector<Json> track;
  for (const Json& t : truth_) track.push_back(Perfect(t));
  Write(dir_ / "perfect.jsonl", track);
  const Score s = ScoreTrack(dir_ / "seq/truth/frames.jsonl", dir_ / "perfect.jsonl");
  EXPECT_EQ(s.truth_frames, int(truth_.size()));
  EXPECT_GT(s.present_frames, 40);
  EXPECT_EQ(s.tracked_frames, s.present_frames);
  for (const auto& [joint, e] : s.joints) {
    EXPECT_EQ(e.mean, 0.0) << joint;
    EXPECT_EQ(e.outliers, 0) << joint;
    EXPECT_EQ(e.missing, 0) << joint;
  }
  EXPECT_EQ(s.joints.at("neck").total, s.present_frames);
  EXPECT_GT(s.pointing.at("right").total, 10);
  EXPECT_LT(s.pointing.at("right").mean, 1e-6);
  EXPECT_EQ(s.rest.at("both").rate(), 1.0);
  EXPECT_EQ(s.motion.rate(), 1.0);
}

// Postures are unordered pairs; a gesture performance is identified by the
// last label the track reports within the truth's run of that gesture.
TEST_F(ScoreTest, PosturesAndGesturesAgainstTheTruthsLabels) {
  std::vector<Json> track;
  int present = 0, gesture_frames = 0, with_pair = 0, wrong = 0;
  for (const Json& t : truth_) {
    Json j = Perfect(t);
    const Json& p = t["labels"]["posture"];
    // The pair reversed (still right), except every fifth frame (wrong).
    const bool make_wrong = t["present"].get<bool>() && present++ % 5 == 0;
    j["posture"] = {{"pair", {p[1], make_wrong ? Json("A9") : p[0]}}};
    if (t["present"].get<bool>()) ++with_pair, wrong += make_wrong;
    // The gesture said on its first frames, then another one at its end.
    if (t["labels"]["gesture"].is_string()) {
      ++gesture_frames;
      j["gesture"] = {{"label", gesture_frames < 20 ? "raise_overhead" : "flap_one"}, {"score", 1}, {"start_frame", 0}};
    }
    track.push_back(j);
  }
  Write(dir_ / "labels.jsonl", track);
  const Score s = ScoreTrack(dir_ / "seq/truth/frames.jsonl", dir_ / "labels.jsonl");
  EXPECT_EQ(s.posture.total, with_pair);
  EXPECT_EQ(s.posture.correct, with_pair - wrong);
  EXPECT_EQ(s.gesture.total, 1);  // one raise_overhead performance
  EXPECT_EQ(s.gesture.correct, 0);
  EXPECT_EQ(s.gesture_confusion.at("raise_overhead").at("flap_one"), 1);
  EXPECT_NE(s.Markdown().find("**Gestures**"), std::string::npos);
  EXPECT_EQ(s.ToJson()["postures"]["total"], with_pair);
}

TEST_F(ScoreTest, ReportsExactlyTheInjectedErrors) {
  std::vector<Json> track;
  std::vector<int> outlier_frames;
  int present = 0, rest_flips = 0, nulls = 0;
  for (const Json& t : truth_) {
    Json j = Perfect(t);
    const int f = t["frame"];
    // A constant 3 cm offset on the right elbow (where it is scored: not at rest).
    j["joints3d"]["right_elbow"][0] = t["joints3d"]["right_elbow"][0].get<double>() + 0.03;
    // Outliers: the neck 40 cm off on every 17th present frame.
    if (t["present"] && present++ % 17 == 5) {
      j["joints3d"]["neck"][2] = t["joints3d"]["neck"][2].get<double>() + 0.40;
      outlier_frames.push_back(f);
    }
    // The right pointing ray turned by exactly 2 degrees about an axis across it.
    if (!t["pointing"]["right"].is_null()) {
      const Eigen::Vector3d d(t["pointing"]["right"]["dir"][0], t["pointing"]["right"]["dir"][1],
                              t["pointing"]["right"]["dir"][2]);
      const Eigen::Vector3d axis = d.cross(Eigen::Vector3d::UnitZ()).normalized();
      const Eigen::Vector3d r = Eigen::AngleAxisd(2.0 * M_PI / 180.0, axis) * d;
      j["pointing"]["right"]["dir"] = {r.x(), r.y(), r.z()};
    }
    // The left rest flag wrong on every 10th frame; the waist missing on every 9th.
    if (t["present"] && f % 10 == 3) {
      j["rest"]["left"] = !t["labels"]["rest"]["left"].get<bool>();
      ++rest_flips;
    }
    if (t["present"] && f % 9 == 4) {
      j["joints3d"]["waist"] = nullptr;
      ++nulls;
    }
    track.push_back(j);
  }
  Write(dir_ / "perturbed.jsonl", track);
  ScoreJobOptions job;
  job.sequence = dir_ / "seq";
  job.track = dir_ / "perturbed.jsonl";
  job.out = dir_ / "score";
  std::string md;
  const fs::path out = RunScoreJob(job, &md);
  const Score s = ScoreTrack(dir_ / "seq/truth/frames.jsonl", dir_ / "perturbed.jsonl");
  const ErrorStats& elbow = s.joints.at("right_elbow");
  EXPECT_NEAR(elbow.mean, 3.0, 1e-9);
  EXPECT_NEAR(elbow.std, 0.0, 1e-9);
  EXPECT_EQ(elbow.outliers, 0);
  const ErrorStats& neck = s.joints.at("neck");
  EXPECT_EQ(neck.outliers, int(outlier_frames.size()));
  EXPECT_EQ(neck.mean, 0.0);  // what is left is exact
  int flagged_right = 0;
  for (const auto& [frame, e, outlier] : s.joint_errors.at("neck")) {
    const bool injected = std::find(outlier_frames.begin(), outlier_frames.end(), frame) != outlier_frames.end();
    EXPECT_EQ(outlier, injected) << "frame " << frame;
    flagged_right += outlier && injected;
  }
  EXPECT_EQ(flagged_right, int(outlier_frames.size()));
  EXPECT_NEAR(s.pointing.at("right").mean, 2.0, 1e-9);
  EXPECT_LT(s.pointing.at("left").mean, 1e-6);
  EXPECT_EQ(s.joints.at("waist").missing, nulls);
  EXPECT_EQ(s.joints.at("waist").total, s.present_frames - nulls);
  EXPECT_EQ(s.rest.at("left").total - s.rest.at("left").correct, rest_flips);
  EXPECT_EQ(s.rest.at("right").rate(), 1.0);
  // The files the job wrote say the same.
  const Json j = Json::parse(irbench::testing::ReadText(out / "score.json"));
  EXPECT_NEAR(j["joints_cm"]["right_elbow"]["mean"].get<double>(), 3.0, 1e-9);
  EXPECT_EQ(j["joints_cm"]["neck"]["outliers"], int(outlier_frames.size()));
  EXPECT_NE(md.find("| Right Elbow | 3.00 | 0.00 | 0 |"), std::string::npos) << md;
  EXPECT_NE(irbench::testing::ReadText(out / "tables.md").find("Table 6.3"), std::string::npos);
  EXPECT_NE(irbench::testing::ReadText(out / "joints.csv").find("right_elbow,3,"), std::string::npos);
}

// irbench track's silhouettes/ beside the track file are scored against the
// truth masks: copies of the masks score IoU 1, and one camera's masks moved a
// pixel to the right score exactly what the move made, all of it within a
// pixel of the true outline.
TEST_F(ScoreTest, SilhouettesBesideTheTrackAreScored) {
  std::vector<Json> track;
  for (const Json& t : truth_) track.push_back(Perfect(t));
  const fs::path folder = dir_ / "with_silhouettes";
  fs::create_directories(folder);
  Write(folder / "track.jsonl", track);
  const fs::path masks = dir_ / "seq/truth/masks";
  std::string moved_camera;
  long moved_truth = 0, moved_false = 0, moved_missed = 0;
  int scored = 0;
  for (const auto& camera : fs::directory_iterator(masks)) {
    const std::string name = camera.path().filename().string();
    if (moved_camera.empty()) moved_camera = name;
    fs::create_directories(folder / "silhouettes" / name);
    for (const auto& file : fs::directory_iterator(camera.path())) {
      cv::Mat mask = cv::imread(file.path().string(), cv::IMREAD_GRAYSCALE);
      ASSERT_FALSE(mask.empty());
      if (cv::countNonZero(mask) > 0) ++scored;
      if (name == moved_camera) {
        cv::Mat moved = cv::Mat::zeros(mask.size(), CV_8U);
        mask.colRange(0, mask.cols - 1).copyTo(moved.colRange(1, mask.cols));
        moved_truth += cv::countNonZero(mask);
        moved_false += cv::countNonZero(moved & ~mask);
        moved_missed += cv::countNonZero(mask & ~moved);
        mask = moved;
      }
      cv::imwrite((folder / "silhouettes" / name / file.path().filename()).string(), mask);
    }
  }
  ASSERT_GT(moved_truth, 0);
  ScoreJobOptions job;
  job.sequence = dir_ / "seq";
  job.track = folder / "track.jsonl";
  job.out = dir_ / "score_silhouettes";
  Score s;
  const fs::path out = RunScoreJob(job, nullptr, &s);
  ASSERT_TRUE(s.silhouettes);
  EXPECT_EQ(int(s.silhouettes->frames.size()), scored);
  EXPECT_EQ(s.silhouettes->missing, 0);
  for (const auto& [camera, summary] : s.silhouettes->ByCamera()) {
    if (camera == moved_camera) {
      EXPECT_LT(summary.iou_median, 1.0);
      EXPECT_DOUBLE_EQ(summary.false_share, double(moved_false) / moved_truth);
      EXPECT_DOUBLE_EQ(summary.missed_share, double(moved_missed) / moved_truth);
      EXPECT_EQ(summary.near_outline_share, 1.0);
    } else {
      EXPECT_DOUBLE_EQ(summary.iou_min, 1.0) << camera;
      EXPECT_DOUBLE_EQ(summary.false_share + summary.missed_share, 0.0) << camera;
    }
  }
  const Json j = Json::parse(irbench::testing::ReadText(out / "score.json"));
  EXPECT_EQ(j["silhouettes"]["camera_frames"], scored);
  EXPECT_NE(irbench::testing::ReadText(out / "tables.md").find("| All | " + std::to_string(scored) + " |"),
            std::string::npos);
  EXPECT_TRUE(fs::is_regular_file(out / "silhouettes.csv"));
  const std::string page = irbench::testing::ReadText(out / "report.html");
  EXPECT_NE(page.find("<table id=\"silhouettes\">"), std::string::npos);
  EXPECT_NE(page.find("<tr><th>All</th><td>" + std::to_string(scored) + "</td>"), std::string::npos);
  if (fs::exists(out / "plots" / "plots.gp")) {  // gnuplot was found
    EXPECT_NE(page.find("id=\"plot-silhouettes_over_time\""), std::string::npos);
    // The plotted series: a line "frame IoU" per scored camera-frame.
    std::ifstream series(out / "plots" / ("silhouette_iou_" + moved_camera + ".dat"));
    int lines = 0;
    for (std::string line; std::getline(series, line);) lines += !line.empty();
    EXPECT_EQ(lines, std::count_if(s.silhouettes->frames.begin(), s.silhouettes->frames.end(),
                                   [&](const SilhouetteCounts& c) { return c.camera == moved_camera; }));
  }
  // A track without silhouettes beside it: none scored, none invented.
  Write(dir_ / "plain.jsonl", track);
  job.track = dir_ / "plain.jsonl";
  job.out = dir_ / "score_plain";
  job.report = false;
  const fs::path plain = RunScoreJob(job, nullptr, &s);
  EXPECT_FALSE(s.silhouettes);
  EXPECT_TRUE(Json::parse(irbench::testing::ReadText(plain / "score.json"))["silhouettes"].is_null());
  EXPECT_FALSE(fs::exists(plain / "silhouettes.csv"));
}

TEST_F(ScoreTest, BadTrackFilesNameTheLine) {
  std::vector<Json> track;
  for (const Json& t : truth_) track.push_back(Perfect(t));
  track[3]["joints3d"]["neck"] = {1, 2};
  Write(dir_ / "bad.jsonl", track);
  try {
    ScoreTrack(dir_ / "seq/truth/frames.jsonl", dir_ / "bad.jsonl");
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "line 4: neck") << e.what();
  }
  irbench::testing::WriteText(dir_ / "bad2.jsonl", "{\"frame\": 0}\n{not json\n");
  try {
    ScoreTrack(dir_ / "seq/truth/frames.jsonl", dir_ / "bad2.jsonl");
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "line 2") << e.what();
  }
  ScoreJobOptions job;
  job.sequence = dir_ / "seq";  // no track/track.jsonl there
  EXPECT_THROW(RunScoreJob(job), InputError);
}

}  // namespace
}  // namespace irbench
