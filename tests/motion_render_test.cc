// Motion capture and the motion library through the renderer: every CMU clip
// beside the checkout retargets onto a person and renders with its visible
// truth joints on the person's mask; a session's truth carries labels,
// pointing and events.

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "sim/motion/retarget.h"
#include "sim/sequence/render_job.h"
#include "sequence_format/manifest.h"
#include "tests/mask_check.h"
#include "tests/test_util.h"

namespace irbench {
namespace {
namespace fs = std::filesystem;
using irbench::testing::FreshTempDir;
using irbench::testing::ReadText;
using irbench::testing::WriteText;

TEST(MotionRenderTest, EveryCmuClipRetargetsAndRenders) {
  const std::vector<fs::path> files = irbench::testing::CmuClips();
  if (files.empty()) GTEST_SKIP() << "no CMU clips in ../shared/data/mocap/cmu";
  const fs::path dir = FreshTempDir("motion_cmu");
  for (const fs::path& clip : files) {
    // Two frames from the middle of the clip through a session script (which
    // trims the clip), on three persons of different heights and builds.
    const fs::path session = dir / (clip.stem().string() + ".json");
    WriteText(session, nlohmann::json{{"format", "irbench.session/1"},
                                      {"items", {{{"clip", clip.string()}, {"start_s", 1.0}}}}}
                           .dump());
    for (const char* person : {"p1", "p2", "p3"}) {
      RenderJobOptions options;
      options.rig = "lab4";
      options.avatar = person;
      options.motion = session.string();
      options.frames = 2;
      options.background_frames = 0;
      options.out = dir / (clip.stem().string() + "_" + person);
      const fs::path seq = RunRenderJob(options);
      int visible = 0;
      const double worst = irbench::testing::WorstVisibleJointOffMask(seq, &visible);
      EXPECT_GT(visible, 10) << clip.filename() << " on " << person;
      EXPECT_LE(worst, 2.0) << clip.filename() << " on " << person;
      const auto manifest = ReadManifest(seq).json;
      EXPECT_EQ(manifest["motion"]["kind"], "session");
      fs::remove_all(seq);
    }
  }
}

TEST(MotionRenderTest, AsfAmcRetargetsAndRenders) {
  const fs::path dir = FreshTempDir("motion_amc");
  WriteText(dir / "07.asf", irbench::testing::CmuStyleAsf());
  WriteText(dir / "07_05.amc", irbench::testing::CmuStyleAmc(30));
  const MocapClip clip = LoadMocap(dir / "07_05.amc");
  EXPECT_EQ(clip.convention, "cmu");
  EXPECT_EQ(clip.frames.size(), 30u);
  EXPECT_NEAR(clip.frame_time, 1.0 / 120, 1e-12);
  for (const char* person : {"p1", "p4"}) {
    const Avatar avatar = LoadAvatar(fs::path(IRBENCH_SOURCE_DIR) / "avatars" / (std::string(person) + ".json"));
    const auto motion = Retarget(clip, avatar.skeleton);
    double worst = 0;
    for (size_t f = 0; f < clip.frames.size(); f += 3) {
      const JointTransforms fk = ForwardKinematics(avatar.skeleton, motion->At(f * clip.frame_time));
      for (int sh : {kRightShoulder, kLeftShoulder}) {
        for (int seg = 0; seg < 2; ++seg) {
          const Eigen::Vector3d src = motion->world_from_source *
                                      (clip.frames[f].position[motion->source_joint[sh + seg + 1]] -
                                       clip.frames[f].position[motion->source_joint[sh + seg]]);
          const Eigen::Vector3d ours = fk[sh + seg + 1].translation() - fk[sh + seg].translation();
          worst = std::max(worst, std::acos(std::clamp(src.normalized().dot(ours.normalized()), -1.0, 1.0)));
        }
      }
    }
    EXPECT_LT(worst * 180 / M_PI, 2.0) << person;
  }
  RenderJobOptions options;
  options.rig = "lab4";
  options.motion = (dir / "07_05.amc").string();
  options.frames = 3;
  options.background_frames = 0;
  options.out = dir / "seq";
  const fs::path seq = RunRenderJob(options);
  int visible = 0;
  EXPECT_LE(irbench::testing::WorstVisibleJointOffMask(seq, &visible), 2.0);
  EXPECT_GT(visible, 10);
  const auto manifest = ReadManifest(seq).json;
  EXPECT_EQ(manifest["motion"]["kind"], "amc");
}

TEST(MotionRenderTest, SessionTruthCarriesLabelsPointingAndEvents) {
  const fs::path dir = FreshTempDir("motion_session");
  const fs::path session = dir / "s.json";
  WriteText(session, R"({"format": "irbench.session/1", "crossfade_s": 0.2, "items": [
    {"motion": "point", "target": "helicopter", "side": "right", "hold_s": 0.5},
    {"motion": "raise_overhead", "side": "left", "hold_s": 0.3}]})");
  RenderJobOptions options;
  options.rig = "lab4";
  options.scene = "theater";
  options.motion = session.string();
  options.background_frames = 0;
  options.out = dir / "seq";
  const fs::path seq = RunRenderJob(options);
  const auto events = nlohmann::json::parse(ReadText(seq / "truth/events.json"));
  ASSERT_EQ(events.size(), 2u);
  EXPECT_EQ(events[0]["kind"], "point");
  EXPECT_EQ(events[0]["value"], "helicopter");
  EXPECT_EQ(events[1]["value"], "raise_overhead");
  std::ifstream truth(seq / "truth/frames.jsonl");
  std::string line;
  int pointing = 0, gesture = 0, frames = 0, left_up = 0;
  while (std::getline(truth, line)) {
    const auto f = nlohmann::json::parse(line);
    ++frames;
    const int n = f["frame"];
    if (n >= events[0]["start_frame"].get<int>() && n <= events[0]["end_frame"].get<int>()) {
      EXPECT_EQ(f["pointing"]["right"]["aimed_at"], "helicopter") << n;
      EXPECT_EQ(f["pointing"]["right"]["target"], "helicopter") << n;
      ++pointing;
    }
    gesture += f["labels"]["gesture"] == "raise_overhead";
    left_up += f["labels"]["posture"][0] == "A2" && f["labels"]["rest"]["right"] == true;
  }
  EXPECT_GT(pointing, 5);
  EXPECT_GE(gesture, events[1]["end_frame"].get<int>() - events[1]["start_frame"].get<int>());
  EXPECT_GT(left_up, 3);
  // The BVH export of the rendered motion has one frame per rendered frame.
  const std::string bvh = ReadText(seq / "truth/motion.bvh");
  EXPECT_NE(bvh.find("Frames: " + std::to_string(frames) + "\n"), std::string::npos);
}

// The occlusion library's poses (thesis Fig. 6.10) do what they say, judged
// by the truth: the hand behind the back is hidden from both frontal cameras
// (and seen by them at rest); the arm across the chest lies over the torso in
// the frontal images (its wrist between the shoulders); crossed forearms put
// each wrist on the other side; hands together meet.
TEST(MotionRenderTest, OcclusionPosesHideWhatTheySay) {
  const fs::path dir = FreshTempDir("motion_occlusion");
  // theater4's two frontal cameras only (the poses are about them).
  nlohmann::json rig = nlohmann::json::parse(ReadText(fs::path(IRBENCH_SOURCE_DIR) / "rigs" / "theater4.json"));
  nlohmann::json frontal = nlohmann::json::array();
  for (const auto& cam : rig["cameras"]) {
    if (cam["name"] == "front_left" || cam["name"] == "front_right") frontal.push_back(cam);
  }
  rig["cameras"] = frontal;
  WriteText(dir / "frontal.json", rig.dump());
  std::map<std::string, nlohmann::json> at_rest, held;
  for (const char* pose : {"arm_behind", "arm_across", "arms_crossed", "hands_together"}) {
    const fs::path session = dir / (std::string(pose) + ".json");
    WriteText(session, nlohmann::json{{"format", "irbench.session/1"},
                                      {"items", {{{"motion", "occlusion"}, {"pose", pose}, {"side", "right"}}}}}
                           .dump());
    RenderJobOptions options;
    options.rig = (dir / "frontal.json").string();
    options.motion = session.string();
    options.frames = 40;  // the pose is held from 1.0 s / tempo (at most 1.18 s) for 2 s / tempo
    options.background_frames = 0;
    options.supersample = 1;
    options.out = dir / pose;
    const fs::path seq = RunRenderJob(options);
    std::ifstream truth(seq / "truth/frames.jsonl");
    std::string line;
    for (int n = 0; std::getline(truth, line); ++n) {
      if (n == 0) at_rest[pose] = nlohmann::json::parse(line);
      if (n == 39) held[pose] = nlohmann::json::parse(line);
    }
  }
  const auto vis = [](const nlohmann::json& f, const char* cam, const char* joint) {
    return f["joints2d"][cam][joint][2].get<int>();
  };
  for (const char* cam : {"front_left", "front_right"}) {
    EXPECT_EQ(vis(at_rest["arm_behind"], cam, "right_wrist"), 2) << cam;
    EXPECT_EQ(vis(held["arm_behind"], cam, "right_wrist"), 1) << cam;
    const nlohmann::json& j = held["arm_across"]["joints2d"][cam];
    const double u = j["right_wrist"][0], a = j["left_shoulder"][0], b = j["right_shoulder"][0];
    const double lo = std::min(a, b), hi = std::max(a, b);
    EXPECT_GT(u, lo) << cam;
    EXPECT_LT(u, hi) << cam;
  }
  // The truth counts the views that see each joint: the arm behind the back
  // hides its wrist from both frontal cameras; at rest both see it.
  EXPECT_EQ(held["arm_behind"]["views"]["right_wrist"], 0);
  EXPECT_EQ(at_rest["arm_behind"]["views"]["right_wrist"], 2);
  for (const auto& frames : {at_rest, held}) {
    for (const auto& [pose, f] : frames) {
      for (const auto& [joint, n] : f["views"].items()) {
        int seen = 0;
        for (const auto& [cam, joints] : f["joints2d"].items()) seen += joints[joint][2].get<int>() == 2;
        EXPECT_EQ(n.get<int>(), seen) << pose << " " << joint;
      }
      EXPECT_EQ(f["views"].size(), f["joints3d"].size()) << pose;
    }
  }
  const auto world = [](const nlohmann::json& f, const char* joint) {
    return Eigen::Vector3d(f["joints3d"][joint][0], f["joints3d"][joint][1], f["joints3d"][joint][2]);
  };
  // The person faces +y, their right is +x: crossed, the right wrist is left of the left wrist.
  EXPECT_LT(world(held["arms_crossed"], "right_wrist").x(), world(held["arms_crossed"], "left_wrist").x());
  EXPECT_GT(world(at_rest["arms_crossed"], "right_wrist").x(), world(at_rest["arms_crossed"], "left_wrist").x());
  EXPECT_LT((world(held["hands_together"], "right_wrist") - world(held["hands_together"], "left_wrist")).norm(), 0.15);
}

}  // namespace
}  // namespace irbench
