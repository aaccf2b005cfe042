// A rig's faults against the tracker (issue 27): one camera goes black,
// freezes, loses frames or writes corrupt files for a span of a rendered
// sequence (irbench fault). The tracker must say which camera it left out
// when, keep tracking through the span with errors near the intact run's,
// and take the camera back after. The demo session's figures (each of the
// four cameras, black and frozen from 2 s to 8 s) are in the issue note.

#include <gtest/gtest.h>

#include <fstream>
#include <map>
#include <nlohmann/json.hpp>

#include "sim/sequence/camera_faults.h"
#include "sim/sequence/render_job.h"
#include "tests/shared_render.h"
#include "tests/test_util.h"
#include "tests/track_figures.h"
#include "tracker/pipeline/track_job.h"

namespace irbench {
namespace {
namespace fs = std::filesystem;
using irbench::testing::FreshTempDir;
using irbench::testing::SharedRender;
using irbench::testing::WriteText;

using irbench::testing::ReadJsonLines;
using Figures = irbench::testing::TrackFigures;

class CameraFaultTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new fs::path(FreshTempDir("camera_fault_" + std::to_string(getpid())));
    WriteText(*dir_ / "session.json", R"({"format": "irbench.session/1", "crossfade_s": 0.2, "items": [
      {"motion": "enter", "to": [0.0, 0.0]},
      {"motion": "direct_traffic", "target": "truck", "cycles": 1}]})");
    RenderJobOptions options;
    options.rig = "theater4";
    options.avatar = "p3";
    options.motion = (*dir_ / "session.json").string();
    options.sensor = "thesis";
    options.background_frames = 12;
    options.supersample = 1;  // a quarter of the render time; the tracker sees the same kind of frames
    options.seed = 11;
    options.out = *dir_ / "seq";
    seq_ = new fs::path(SharedRender("fault_session", options));
    truth_ = new std::vector<nlohmann::json>(ReadJsonLines(*seq_ / "truth/frames.jsonl"));
  }
  static void TearDownTestSuite() {
    fs::remove_all(*dir_);
    delete dir_;
    delete seq_;
    delete truth_;
  }

  static std::vector<nlohmann::json> Track(const fs::path& seq, const std::string& name) {
    TrackJobOptions options;
    options.sequence = seq;
    options.out = *dir_ / name;
    return ReadJsonLines(RunTrackJob(options) / "track.jsonl");
  }
  static fs::path Fault(const std::string& spec, const std::string& name) {
    FaultJobOptions options;
    options.sequence = *seq_;
    options.out = *dir_ / name;
    options.faults = {ParseCameraFault(spec, "--fault")};
    return RunFaultJob(options);
  }
  static Figures Score(const std::vector<nlohmann::json>& track) {
    return irbench::testing::UpperBodyFigures(track, *truth_);
  }
  // The frames on which `camera` was left out, and why.
  static std::map<int, std::string> LeftOut(const std::vector<nlohmann::json>& track, const std::string& camera) {
    std::map<int, std::string> out;
    for (const nlohmann::json& line : track) {
      if (line["cameras_left_out"].contains(camera)) out[line["frame"]] = line["cameras_left_out"][camera];
    }
    return out;
  }
  // The span [first, end) in frames of a fault from `from_s` to `to_s`.
  static std::pair<int, int> Span(double from_s, double to_s) { return {int(from_s * 30), int(to_s * 30)}; }

  static fs::path* dir_;
  static fs::path* seq_;
  static std::vector<nlohmann::json>* truth_;
};
fs::path* CameraFaultTest::dir_ = nullptr;
fs::path* CameraFaultTest::seq_ = nullptr;
std::vector<nlohmann::json>* CameraFaultTest::truth_ = nullptr;

// Each test renders its own copy (CTest runs them apart): the black and the
// frozen camera share one test and one intact run.
TEST_F(CameraFaultTest, ABlackOrFrozenCameraIsLeftOutWhileBadAndTrackingGoesOn) {
  const std::vector<nlohmann::json> intact_track = Track(*seq_, "intact-track");
  ASSERT_EQ(intact_track.size(), truth_->size());
  for (const nlohmann::json& line : intact_track) EXPECT_TRUE(line["cameras_left_out"].empty()) << line["frame"];
  const Figures intact = Score(intact_track);
  EXPECT_GT(intact.Fraction(), 0.8);
  // 6.27 cm since the elbows' backward cap (6.52 with a cap at 0.2, under
  // 6.0 without): this p3 direct_traffic session is one of the library
  // motions the cap costs; over the full suite it gains on real motion and
  // is level on the library's over three seeds (docs/tracker.md, Body).
  EXPECT_LT(intact.mean_error_cm, 6.5);
  const auto [first, end] = Span(1.5, 3.5);
  {
    // The side camera black from 1.5 s to 3.5 s: in the middle of the gesture.
    const std::vector<nlohmann::json> track = Track(Fault("side:black:1.5-3.5", "side-black"), "side-black-track");
    const std::map<int, std::string> left_out = LeftOut(track, "side");
    ASSERT_EQ(static_cast<int>(left_out.size()), end - first);
    EXPECT_EQ(left_out.begin()->first, first);
    EXPECT_EQ(left_out.rbegin()->first, end - 1);
    for (const auto& [frame, why] : left_out) EXPECT_EQ(why, "dark") << frame;
    const Figures f = Score(track);
    EXPECT_NEAR(f.Fraction(), intact.Fraction(), 0.05);
    EXPECT_LT(f.mean_error_cm, 1.5 * intact.mean_error_cm) << "intact " << intact.mean_error_cm;
    // The copy's faults.json says what was done.
    const nlohmann::json record =
        nlohmann::json::parse(irbench::testing::ReadText(*dir_ / "side-black/faults.json"));
    EXPECT_EQ(record["faults"][0]["camera"], "side");
    EXPECT_EQ(record["faults"][0]["frames"], end - first);
  }
  {
    const std::vector<nlohmann::json> track =
        Track(Fault("front_left:freeze:1.5-3.5", "fl-freeze"), "fl-freeze-track");
    const std::map<int, std::string> left_out = LeftOut(track, "front_left");
    // The span's first frame is the one repeated; the second repeat (its
    // third frame) is the first found frozen (CameraHealthOptions::frozen_frames).
    ASSERT_EQ(static_cast<int>(left_out.size()), end - first - 2);
    EXPECT_EQ(left_out.begin()->first, first + 2);
    for (const auto& [frame, why] : left_out) EXPECT_EQ(why, "frozen") << frame;
    const Figures f = Score(track);
    EXPECT_NEAR(f.Fraction(), intact.Fraction(), 0.05);
    EXPECT_LT(f.mean_error_cm, 1.5 * intact.mean_error_cm) << "intact " << intact.mean_error_cm;
  }
}

TEST_F(CameraFaultTest, LostAndCorruptFramesAreSkippedNotFatal) {
  // The overhead camera loses a third of a second; front_right writes one
  // undecodable file; the run goes on and says so.
  FaultJobOptions options;
  options.sequence = *seq_;
  options.out = *dir_ / "lost";
  options.faults = {ParseCameraFault("overhead:drop:2-2.34", "--fault"),
                    ParseCameraFault("front_right:corrupt:2.5-2.51", "--fault")};
  const std::vector<nlohmann::json> track = Track(RunFaultJob(options), "lost-track");
  ASSERT_EQ(track.size(), truth_->size());
  const std::map<int, std::string> overhead = LeftOut(track, "overhead");
  ASSERT_EQ(overhead.size(), 11u);
  EXPECT_EQ(overhead.begin()->first, 60);
  for (const auto& [frame, why] : overhead) EXPECT_EQ(why, "missing") << frame;
  const std::map<int, std::string> front_right = LeftOut(track, "front_right");
  ASSERT_EQ(front_right.size(), 1u);
  EXPECT_EQ(front_right.begin()->first, 75);
  EXPECT_EQ(front_right.begin()->second, "missing");
  for (int f = 60; f < 76; ++f) {
    if ((*truth_)[f]["present"].get<bool>()) {
      EXPECT_EQ(track[f]["state"], "tracking") << f;
    }
  }
  // Bad fault specs and outputs.
  EXPECT_THROW(ParseCameraFault("side:melt:1-2", "--fault"), InputError);
  EXPECT_THROW(ParseCameraFault("side:black:2-1", "--fault"), InputError);
  EXPECT_THROW(ParseCameraFault("side:black:nan-1", "--fault"), InputError);
  EXPECT_THROW(ParseCameraFault("side", "--fault"), InputError);
  EXPECT_THROW(Fault("nocam:black:1-2", "nocam"), InputError);
  EXPECT_THROW(Fault("side:black:100-200", "late"), InputError);
  // Never inside the sequence it copies; the original untouched.
  FaultJobOptions inside;
  inside.sequence = *seq_;
  inside.out = *seq_ / "frames" / "copy";
  inside.faults = {ParseCameraFault("side:black:1-2", "--fault")};
  EXPECT_THROW(RunFaultJob(inside), InputError);
  EXPECT_FALSE(fs::exists(*seq_ / "frames" / "copy"));
  EXPECT_TRUE(fs::exists(*seq_ / "frames" / "overhead" / "000060.png"));
}

}  // namespace
}  // namespace irbench
