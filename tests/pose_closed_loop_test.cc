// Pose tracking against the truth on a rendered sequence (issue 7's short CI
// case): theater4, the `thesis` sensor preset, a person walking in, pointing
// at a screen target, raising an arm and directing traffic. The tracker sees
// only frames, calibration and empty-stage frames (SequenceInput); this test
// reads the truth to score it. The full figures (five persons, the demo
// session) are in the issue notes, made with `irbench demo` / `irbench score`.

#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>

#include "sim/sequence/render_job.h"
#include "tests/shared_render.h"
#include "tests/test_util.h"
#include "tracker/frontend/frontend.h"
#include "tracker/io/sequence_input.h"
#include "tracker/pose/pose_tracker.h"

namespace irbench {
namespace {
namespace fs = std::filesystem;
using irbench::testing::FreshTempDir;
using irbench::testing::SharedRender;
using irbench::testing::WriteText;

Eigen::Vector3d V(const nlohmann::json& j) { return {j[0].get<double>(), j[1].get<double>(), j[2].get<double>()}; }

int ModelIndex(const std::string& name) {
  for (int j = 0; j < kModelJointCount; ++j) {
    if (name == ModelJointName(j)) return j;
  }
  return -1;
}

double Mean(const std::vector<double>& v) {
  double s = 0;
  for (double x : v) s += x;
  return v.empty() ? 0 : s / v.size();
}

class PoseClosedLoopTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new fs::path(FreshTempDir("pose_closed_loop_" + std::to_string(getpid())));
    WriteText(*dir_ / "session.json", R"({"format": "irbench.session/1", "crossfade_s": 0.2, "items": [
      {"motion": "enter", "to": [0.0, 0.0]},
      {"motion": "point", "target": "helicopter", "hold_s": 0.6},
      {"motion": "raise_overhead", "hold_s": 0.3},
      {"motion": "direct_traffic", "target": "truck", "cycles": 1}]})");
    RenderJobOptions options;
    options.rig = "theater4";
    options.avatar = "p2";
    options.motion = (*dir_ / "session.json").string();
    options.sensor = "thesis";
    options.background_frames = 12;
    options.seed = 5;
    options.out = *dir_ / "seq";
    seq_ = new fs::path(SharedRender("pose_session", options));
    std::ifstream in(*seq_ / "truth/frames.jsonl");
    truth_ = new std::vector<nlohmann::json>;
    for (std::string line; std::getline(in, line);) truth_->push_back(nlohmann::json::parse(line));
  }
  static void TearDownTestSuite() {
    fs::remove_all(*dir_);
    delete dir_;
    delete seq_;
    delete truth_;
  }
  // The first frame with every scored joint inside every camera's image.
  static int FullyInside() {
    for (const nlohmann::json& t : *truth_) {
      if (!t["present"].get<bool>()) continue;
      bool inside = true;
      for (const auto& [cam, joints] : t["joints2d"].items()) {
        for (const char* j : {"root", "waist", "neck", "head", "left_shoulder", "right_shoulder"}) {
          inside &= joints[j][2].get<int>() > 0;
        }
      }
      if (inside) return t["frame"].get<int>();
    }
    return -1;
  }
  static double RootError(const PoseEstimate& e, const nlohmann::json& t) {
    return (e.body.joints[kModelRoot] - V(t["joints3d"]["root"])).norm();
  }
  static double WaistError(const PoseEstimate& e, const nlohmann::json& t) {
    return (e.body.joints[kModelWaist] - V(t["joints3d"]["waist"])).norm();
  }

  static fs::path* dir_;
  static fs::path* seq_;
  static std::vector<nlohmann::json>* truth_;
};
fs::path* PoseClosedLoopTest::dir_ = nullptr;
fs::path* PoseClosedLoopTest::seq_ = nullptr;
std::vector<nlohmann::json>* PoseClosedLoopTest::truth_ = nullptr;

// The filter is random (seeded): one seed is one sample of its accuracy, and
// a single unlucky seed can lose an arm for a few frames. The errors are
// pooled over three seeds of the filter on the same frames.
TEST_F(PoseClosedLoopTest, JointsPointingAndStartFromAnEmptyStage) {
  const SequenceInput input = SequenceInput::Open(*seq_);
  const FrontEnd front_end = FrontEnd::Train(input, {});
  std::map<std::string, std::vector<double>> errors;
  std::vector<double> pointing_deg;
  const int inside = FullyInside();
  ASSERT_GT(inside, 0) << "the person should walk in from outside the views";
  // Three filters, one per seed, step through the same features.
  const std::vector<uint64_t> seeds = {1, 2, 3};
  std::vector<PoseTracker> trackers;
  // The shipped rest-state SVM (thesis 6.4), trained on other motions' truth.
  const auto rest = std::make_shared<const RestClassifier>(RestClassifier::Load(DefaultRestModelPath()));
  for (uint64_t seed : seeds) {
    PoseTrackerOptions options;
    options.seed = seed;
    trackers.emplace_back(input.cameras(), input.screens(), options);
    trackers.back().set_rest_classifier(rest);
  }
  int rest_correct = 0, rest_total = 0;
  std::vector<int> first_tracking(seeds.size(), -1), first_root(seeds.size(), -1);
  for (int f = 0; f < input.frame_count(); ++f) {
    const std::vector<cv::Mat> images = input.FrameSet(f);
    const FrameFeatures features = front_end.Process(f, images);
    for (size_t s = 0; s < seeds.size(); ++s) {
      const PoseEstimate e = trackers[s].Step(features, 1.0 / input.fps());
      const nlohmann::json& t = (*truth_)[f];
      if (!t["present"].get<bool>()) continue;
      // Tracking has started once the tracker says so and the body is on
      // the person: the waist, the model's own position, within 10 cm. (Not
      // the root: the truth's root is the floor point under the ankles'
      // midpoint, the model's under the waist, and while the user walks in
      // these lie 10-17 cm apart with the model on target.)
      if (first_tracking[s] < 0 && e.tracking && WaistError(e, t) < 0.10) first_tracking[s] = f;
      if (first_root[s] < 0 && e.tracking && RootError(e, t) < 0.10) first_root[s] = f;
      if (f < inside + 10 || !e.tracking) continue;
      for (const char* name : {"root", "waist", "neck", "left_shoulder", "right_shoulder"}) {
        errors[name].push_back((e.body.joints[ModelIndex(name)] - V(t["joints3d"][name])).norm());
      }
      for (const char* side : {"left", "right"}) {
        const auto& rest_decision = e.rest[std::string(side) == "right" ? 0 : 1];
        if (rest_decision) {
          rest_correct += *rest_decision == t["labels"]["rest"][side].get<bool>();
          ++rest_total;
        }
        if (t["labels"]["rest"][side].get<bool>()) continue;  // thesis 6.6 scores moving arms
        for (const char* j : {"elbow", "wrist"}) {
          const std::string name = std::string(side) + "_" + j;
          errors[name].push_back((e.body.joints[ModelIndex(name)] - V(t["joints3d"][name])).norm());
        }
        const nlohmann::json& ray = t["pointing"][side];
        const auto& tracked = e.pointing[std::string(side) == "right" ? 0 : 1];
        if (!ray.is_null() && tracked) {
          pointing_deg.push_back(std::acos(std::clamp(tracked->dir.dot(V(ray["dir"]).normalized()), -1.0, 1.0)) *
                                 180 / M_PI);
        }
      }
    }
  }
  for (size_t s = 0; s < seeds.size(); ++s) {
    ASSERT_GE(first_tracking[s], 0) << "seed " << seeds[s];
    std::printf("seed %d: fully inside at frame %d, tracking (waist within 10 cm) from frame %d, the root within "
                "10 cm from frame %d\n",
                static_cast<int>(seeds[s]), inside, first_tracking[s], first_root[s]);
    // Issue 7's bar: within 10 frames of fully entering. Measured: 6 frames
    // for each of seeds 1-3 (the root within 10 cm: 6, 18 and 6 frames, the
    // user still walking).
    EXPECT_LE(first_tracking[s], inside + 10) << "seed " << seeds[s] << ", fully inside at " << inside;
  }
  for (const auto& [name, e] : errors) {
    RecordProperty(name + "_mean_cm", std::to_string(Mean(e) * 100));
    std::printf("%-16s mean %5.2f cm over %zu frames\n", name.c_str(), Mean(e) * 100, e.size());
  }
  std::printf("pointing         mean %5.2f deg over %zu frames\n", Mean(pointing_deg), pointing_deg.size());
  const double rest_accuracy = rest_total ? static_cast<double>(rest_correct) / rest_total : 0.0;
  RecordProperty("rest_accuracy", std::to_string(rest_accuracy));
  std::printf("rest state       %5.1f %% of %d arm-frames\n", 100 * rest_accuracy, rest_total);
  // Issue 7's bars are 5 cm for shoulders, elbows and wrists, 4 cm for waist
  // and neck, 5 cm for the root, 3 deg pointing. Measured on these frames,
  // seeds 1-3 pooled (the issue note), with the rest-state SVM, the waist
  // cap, the girth up to 2.4 and the spine behind the trunk's middle: arm
  // joints 2.7-3.9 cm, waist 3.9, neck 2.6, root 3.2, pointing 2.1 deg
  // (small changes move these by about half a centimetre either way). The
  // thresholds guard that with a margin; the bars not yet met are named in
  // the issue note.
  for (const char* arm : {"left_shoulder", "right_shoulder", "left_elbow", "right_elbow", "left_wrist",
                          "right_wrist"}) {
    if (errors[arm].size() < 30) continue;  // an arm that never moved
    EXPECT_LT(Mean(errors[arm]), 0.06) << arm;
  }
  EXPECT_LT(Mean(errors["waist"]), 0.05);
  EXPECT_LT(Mean(errors["neck"]), 0.045);
  EXPECT_LT(Mean(errors["root"]), 0.045);
  ASSERT_GT(pointing_deg.size(), 30u);
  EXPECT_LT(Mean(pointing_deg), 3.5);
  // Issue 7's bar is 98.95 %. Measured here, seeds 1-3 pooled: 98.7 %
  // (98.6 % before an arm the axis points show was judged by their angle;
  // the SVM alone, without the likelihood-ratio test: 90.8 % before the
  // spine offset).
  EXPECT_GT(rest_total, 1000);
  EXPECT_GT(rest_accuracy, 0.98);
}

// Thesis 6.6 reports recovery in 2-3 frames after a loss: scatter the
// particles over the stage and count frames until the body is found again:
// the root within 8 cm of the truth, or no further from it than a tracker
// that was never scattered (+2 cm), fed the same features. During the
// walk-in the tracker's own root error swings between 5 and 17 cm, and a
// scattering there would otherwise measure that, not the recovery.
TEST_F(PoseClosedLoopTest, RecoversWithinThreeFramesAfterTheParticlesAreScattered) {
  const SequenceInput input = SequenceInput::Open(*seq_);
  const FrontEnd front_end = FrontEnd::Train(input, {});
  PoseTracker tracker(input.cameras(), input.screens(), {});
  PoseTracker undisturbed(input.cameras(), input.screens(), {});
  const int inside = FullyInside();
  std::vector<int> recovery;
  int scattered_at = -1;
  bool on_target = false;  // the previous frame's root within 8 cm
  for (int f = 0; f < input.frame_count(); ++f) {
    const std::vector<cv::Mat> images = input.FrameSet(f);
    // Scatter a tracker that was on target, every 25 frames once inside.
    if (f > inside + 15 && (f - inside) % 25 == 0 && on_target && scattered_at < 0) {
      tracker.Scatter();
      scattered_at = f;
    }
    const FrameFeatures features = front_end.Process(f, images);
    const PoseEstimate e = tracker.Step(features, 1.0 / input.fps());
    const PoseEstimate reference = undisturbed.Step(features, 1.0 / input.fps());
    const bool present = (*truth_)[f]["present"].get<bool>();
    on_target = e.tracking && present && RootError(e, (*truth_)[f]) < 0.08;
    const double allowed =
        reference.tracking && present ? std::max(0.08, RootError(reference, (*truth_)[f]) + 0.02) : 0.08;
    if (scattered_at >= 0 && e.tracking && present && RootError(e, (*truth_)[f]) < allowed) {
      recovery.push_back(f - scattered_at + 1);
      scattered_at = -1;
    } else if (scattered_at >= 0 && f - scattered_at >= 10) {
      recovery.push_back(99);
      scattered_at = -1;
    }
  }
  ASSERT_GE(recovery.size(), 2u);
  std::printf("frames to recover after each scattering:");
  for (int r : recovery) std::printf(" %d", r);
  std::printf("\n");
  for (int r : recovery) EXPECT_LE(r, 3);
}

// A user facing away from the screen: the silhouettes look the same turned
// round, and the screen's heading prior alone tracks CMU's wave hello
// (141_16, which faces away from the screen) turned round throughout. The
// feet, read off the hull, show which way the user faces. (They do not
// always: where the floor layer is mostly the hull's phantom volume its
// centroid can point anywhere — a library flap on p3 at heading 170 deg
// read backwards in 7 frames of 10: docs/tracker.md.)
TEST(PoseFacingTest, TheWaveFacingAwayFromTheScreenIsNotTurnedRound) {
  const std::vector<fs::path> clips = irbench::testing::CmuClips();
  const auto clip = std::find_if(clips.begin(), clips.end(), [](const fs::path& p) { return p.stem() == "141_16"; });
  if (clip == clips.end()) GTEST_SKIP() << "no CMU clip 141_16 in ../shared/data/mocap/cmu";
  const fs::path dir = FreshTempDir("pose_facing_" + std::to_string(getpid()));
  RenderJobOptions options;
  options.rig = "theater4";
  options.avatar = "p3";
  options.motion = clip->string();
  options.sensor = "thesis";
  options.background_frames = 12;
  options.frames = 60;
  options.seed = 3;
  options.out = dir / "seq";
  const fs::path seq = RunRenderJob(options);
  std::vector<nlohmann::json> truth;
  std::ifstream in(seq / "truth/frames.jsonl");
  for (std::string line; std::getline(in, line);) truth.push_back(nlohmann::json::parse(line));
  const SequenceInput input = SequenceInput::Open(seq);
  const FrontEnd front_end = FrontEnd::Train(input, {});
  PoseTrackerOptions feet_options, screen_options;
  screen_options.heading_from_feet = false;
  PoseTracker feet(input.cameras(), input.screens(), feet_options);
  PoseTracker screen(input.cameras(), input.screens(), screen_options);
  std::vector<double> feet_errors, screen_errors;
  for (int f = 0; f < input.frame_count(); ++f) {
    const FrameFeatures features = front_end.Process(f, input.FrameSet(f));
    const PoseEstimate a = feet.Step(features, 1.0 / input.fps());
    const PoseEstimate b = screen.Step(features, 1.0 / input.fps());
    if (f < 5 || !truth[f]["present"].get<bool>()) continue;
    for (const char* name : {"left_shoulder", "right_shoulder"}) {
      const Eigen::Vector3d t = V(truth[f]["joints3d"][name]);
      if (a.tracking) feet_errors.push_back((a.body.joints[ModelIndex(name)] - t).norm());
      if (b.tracking) screen_errors.push_back((b.body.joints[ModelIndex(name)] - t).norm());
    }
  }
  std::printf("shoulders: %.1f cm with the feet, %.1f cm facing the screen (%zu, %zu samples)\n",
              Mean(feet_errors) * 100, Mean(screen_errors) * 100, feet_errors.size(), screen_errors.size());
  ASSERT_GT(feet_errors.size(), 80u);
  // Turned round, the shoulders are a shoulder width off (about 35 cm): the
  // screen's prior alone measured 38.9 cm here (printed above, not asserted).
  EXPECT_LT(Mean(feet_errors), 0.08);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace irbench
