// Closed loop on rendered sequences: the written calibration reproduces every
// truth pixel with OpenCV, visible joints lie on the person, renders are
// byte-identical for the same inputs.

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "common/atomic_file.h"
#include "sim/sequence/render_job.h"
#include "tests/test_util.h"

namespace irbench {
namespace {
namespace fs = std::filesystem;
using irbench::testing::FreshTempDir;
using irbench::testing::ReadText;
using irbench::testing::WriteText;

fs::path RenderFast(const std::string& rig, GlBackend backend, const fs::path& dir,
                    const std::string& name, const std::string& sensor = "clean", uint64_t seed = 1) {
  const fs::path motion = dir / "fast.json";
  WriteText(motion, irbench::testing::FastMotionJson());
  RenderJobOptions options;
  options.rig = rig;
  options.motion = motion.string();
  options.frames = 7;
  options.background_frames = 2;
  options.out = dir / name;
  options.backend = backend;
  options.write_depth = true;
  options.sensor = sensor;
  options.seed = seed;
  return RunRenderJob(options);
}

class SequenceTest : public ::testing::TestWithParam<std::string> {};

TEST_P(SequenceTest, CalibrationReproducesTruthPixelsAndVisibleJointsLieOnThePerson) {
  const fs::path dir = FreshTempDir("seq_" + GetParam());
  const fs::path seq = RenderFast(GetParam(), GlBackend::kAuto, dir, "seq");
  ASSERT_TRUE(fs::exists(seq / "manifest.json"));
  const auto manifest = nlohmann::json::parse(ReadText(seq / "manifest.json"));

  cv::FileStorage intri((seq / "calib/intri.yml").string(), cv::FileStorage::READ);
  cv::FileStorage extri((seq / "calib/extri.yml").string(), cv::FileStorage::READ);
  ASSERT_TRUE(intri.isOpened() && extri.isOpened());
  std::vector<std::string> names;
  intri["names"] >> names;
  ASSERT_EQ(names.size(), manifest["cameras"].size());

  std::ifstream truth(seq / "truth/frames.jsonl");
  std::string line;
  int lines = 0, checked = 0, visible = 0, occluded = 0;
  double worst_px = 0, worst_mask_px = 0;
  while (std::getline(truth, line)) {
    const auto frame = nlohmann::json::parse(line);
    const int f = frame["frame"];
    ++lines;
    std::vector<std::string> joint_names;
    std::vector<cv::Point3d> points;
    for (const auto& [joint, xyz] : frame["joints3d"].items()) {
      joint_names.push_back(joint);
      points.emplace_back(xyz[0], xyz[1], xyz[2]);
    }
    for (const std::string& cam : names) {
      cv::Mat k, dist, rvec, tvec;
      intri["K_" + cam] >> k;
      intri["dist_" + cam] >> dist;
      extri["R_" + cam] >> rvec;
      extri["T_" + cam] >> tvec;
      std::vector<cv::Point2d> projected;
      cv::projectPoints(points, rvec, tvec, k, dist, projected);
      char file[32];
      std::snprintf(file, sizeof(file), "%06d.png", f);
      const cv::Mat mask = cv::imread((seq / "truth/masks" / cam / file).string(), cv::IMREAD_UNCHANGED);
      ASSERT_FALSE(mask.empty());
      // Distance (px) from every pixel to the nearest mask pixel.
      cv::Mat distance;
      cv::distanceTransform(255 - mask, distance, cv::DIST_L2, cv::DIST_MASK_PRECISE);
      for (size_t j = 0; j < joint_names.size(); ++j) {
        const auto& uvv = frame["joints2d"][cam][joint_names[j]];
        const double err = std::hypot(double(uvv[0]) - projected[j].x, double(uvv[1]) - projected[j].y);
        worst_px = std::max(worst_px, err);
        EXPECT_LT(err, 0.01) << cam << " " << joint_names[j];
        ++checked;
        const int vis = uvv[2];
        if (vis == 1) ++occluded;
        if (vis != 2) continue;
        ++visible;
        if (joint_names[j] == "root") continue;  // a floor point, not on the body
        const int u = int(std::lround(double(uvv[0]))), v = int(std::lround(double(uvv[1])));
        ASSERT_TRUE(u >= 0 && v >= 0 && u < mask.cols && v < mask.rows);
        const double off_mask = distance.at<float>(v, u);
        worst_mask_px = std::max(worst_mask_px, off_mask);
        EXPECT_LE(off_mask, 2.0) << cam << " frame " << f << " " << joint_names[j];
      }
    }
  }
  EXPECT_EQ(lines, 7);
  EXPECT_GT(visible, checked / 3);
  std::printf("%s: %d projections, max |cv::projectPoints - joints2d| = %.2e px; %d visible, %d "
              "occluded; max distance of a visible joint from the mask %.2f px\n",
              GetParam().c_str(), checked, worst_px, visible, occluded, worst_mask_px);
  // Depth files exist for every frame and camera.
  EXPECT_TRUE(fs::exists(seq / "truth/depth" / names[0] / "000006.exr"));
}

INSTANTIATE_TEST_SUITE_P(Rigs, SequenceTest,
                         ::testing::Values("theater4", "theater5", "flatworld4", "lab4"));

cv::Mat ReadDepthExr(const fs::path& path) {
  Imf::InputFile file(path.c_str());
  const Imath::Box2i window = file.header().dataWindow();
  cv::Mat depth(window.max.y - window.min.y + 1, window.max.x - window.min.x + 1, CV_32FC1);
  Imf::FrameBuffer frame_buffer;
  frame_buffer.insert("Z", Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(depth.data), sizeof(float),
                                      sizeof(float) * depth.cols));
  file.setFrameBuffer(frame_buffer);
  file.readPixels(window.min.y, window.max.y);
  return depth;
}

// The depth EXR opens with OpenEXR and, at every visible joint, holds the
// camera depth of a surface just in front of that joint.
TEST(SequenceDepthTest, ExrDepthAgreesWithTruthJoints) {
  const fs::path dir = FreshTempDir("seq_depth");
  const fs::path seq = RenderFast("theater4", GlBackend::kAuto, dir, "seq");
  cv::FileStorage extri((seq / "calib/extri.yml").string(), cv::FileStorage::READ);
  std::ifstream truth(seq / "truth/frames.jsonl");
  std::string line;
  int checked = 0;
  while (std::getline(truth, line)) {
    const auto frame = nlohmann::json::parse(line);
    char file[32];
    std::snprintf(file, sizeof(file), "%06d.exr", int(frame["frame"]));
    for (const auto& [cam, joints] : frame["joints2d"].items()) {
      const cv::Mat depth = ReadDepthExr(seq / "truth/depth" / cam / file);
      ASSERT_EQ(depth.cols, 320);
      cv::Mat rot, tvec;
      extri["Rot_" + cam] >> rot;
      extri["T_" + cam] >> tvec;
      for (const auto& [joint, uvv] : joints.items()) {
        if (int(uvv[2]) != 2 || joint == "root") continue;
        const auto& p = frame["joints3d"][joint];
        const cv::Mat p_in_cam = rot * (cv::Mat_<double>(3, 1) << p[0], p[1], p[2]) + tvec;
        // Near the joint, some surface seen lies in front of it by less than a
        // body radius (the visibility rule, docs/truth.md, looks within one
        // pixel in the supersampled render; the EXR holds one nearest sample
        // per pixel, which can fall beside a thin limb, hence two pixels here).
        const int u = int(std::lround(double(uvv[0]))), v = int(std::lround(double(uvv[1])));
        bool found = false;
        for (int dv = -2; dv <= 2; ++dv) {
          for (int du = -2; du <= 2; ++du) {
            if (u + du < 0 || v + dv < 0 || u + du >= depth.cols || v + dv >= depth.rows) continue;
            const double in_front = p_in_cam.at<double>(2) - depth.at<float>(v + dv, u + du);
            found = found || (in_front > -0.05 && in_front < 0.2);
          }
        }
        EXPECT_TRUE(found) << cam << " " << joint;
        ++checked;
      }
    }
  }
  EXPECT_GT(checked, 100);
}

std::map<std::string, uint64_t> HashTree(const fs::path& root) {
  std::map<std::string, uint64_t> hashes;
  for (const auto& e : fs::recursive_directory_iterator(root)) {
    if (e.is_regular_file()) {
      hashes[fs::relative(e.path(), root).string()] = Fnv1a64(ReadText(e.path()));
    }
  }
  return hashes;
}

class DeterminismTest : public ::testing::TestWithParam<GlBackend> {};

TEST_P(DeterminismTest, SameInputsGiveByteIdenticalFiles) {
  const fs::path dir = FreshTempDir("det_" + GlBackendName(GetParam()));
  const auto a = HashTree(RenderFast("theater4", GetParam(), dir, "a"));
  const auto b = HashTree(RenderFast("theater4", GetParam(), dir, "b"));
  ASSERT_GT(a.size(), 50u);
  EXPECT_EQ(a, b);
}

// With the sensor model on, the seed decides every noise field: the same seed
// gives the same bytes, another seed other frames; masks and truth joints do
// not depend on the sensor.
TEST(SensorSequenceTest, SeedDecidesTheNoise) {
  const fs::path dir = FreshTempDir("seq_sensor");
  const auto a = HashTree(RenderFast("theater4", GlBackend::kAuto, dir, "a", "thesis", 3));
  const auto b = HashTree(RenderFast("theater4", GlBackend::kAuto, dir, "b", "thesis", 3));
  const auto c = HashTree(RenderFast("theater4", GlBackend::kAuto, dir, "c", "thesis", 4));
  EXPECT_EQ(a, b);
  EXPECT_NE(a.at("frames/side/000003.png"), c.at("frames/side/000003.png"));
  EXPECT_NE(a.at("background/side/000001.png"), c.at("background/side/000001.png"));
  EXPECT_EQ(a.at("truth/masks/side/000003.png"), c.at("truth/masks/side/000003.png"));
  // The frames are grainy: two empty-stage frames of one camera differ.
  const cv::Mat bg0 = cv::imread((dir / "a/background/side/000000.png").string(), cv::IMREAD_UNCHANGED);
  const cv::Mat bg1 = cv::imread((dir / "a/background/side/000001.png").string(), cv::IMREAD_UNCHANGED);
  EXPECT_GT(cv::norm(bg0, bg1, cv::NORM_L1) / bg0.total(), 0.2);
  const auto truth = nlohmann::json::parse(ReadText(dir / "a/truth/background.jsonl").substr(0, ReadText(dir / "a/truth/background.jsonl").find('\n')));
  EXPECT_TRUE(truth["sensor"]["side"].contains("flicker"));
}

// Per-camera knobs from the rig: a camera that drops frames repeats its last
// image and says so in the truth; motion blur changes the frames but not the
// masks or the truth.
TEST(SensorSequenceTest, DroppedFramesAndMotionBlurFromRigOverrides) {
  const fs::path dir = FreshTempDir("seq_capture");
  auto rig = nlohmann::json::parse(ReadText(std::string(IRBENCH_SOURCE_DIR) + "/rigs/theater4.json"));
  rig["cameras"][0]["sensor"] = {{"capture", {{"drop_rate", 0.5}}}};
  rig["cameras"][1]["sensor"] = {{"optics", {{"motion_blur_samples", 3}}}};
  rig["cameras"][2]["sensor"] = {{"capture", {{"sync_jitter_ms", 20.0}}}};
  WriteText(dir / "rig.json", rig.dump());
  WriteText(dir / "fast.json", irbench::testing::FastMotionJson());
  RenderJobOptions options;
  options.rig = (dir / "rig.json").string();
  options.motion = (dir / "fast.json").string();
  options.frames = 7;
  options.background_frames = 0;
  options.sensor = "thesis";
  options.out = dir / "seq";
  const fs::path seq = RunRenderJob(options);
  std::ifstream truth(seq / "truth/frames.jsonl");
  std::string line;
  int dropped = 0;
  double jitter_sum = 0;
  while (std::getline(truth, line)) {
    const auto frame = nlohmann::json::parse(line);
    const int f = frame["frame"];
    EXPECT_FALSE(bool(frame["sensor"]["side"]["dropped"]));
    EXPECT_EQ(double(frame["sensor"]["side"]["sync_offset_ms"]), 0.0);
    jitter_sum += std::abs(double(frame["sensor"]["overhead"]["sync_offset_ms"]));
    if (!bool(frame["sensor"]["front_left"]["dropped"])) continue;
    ++dropped;
    char now[16], before[16];
    std::snprintf(now, sizeof(now), "%06d.png", f);
    std::snprintf(before, sizeof(before), "%06d.png", f - 1);
    EXPECT_EQ(ReadText(seq / "frames/front_left" / now), ReadText(seq / "frames/front_left" / before));
  }
  EXPECT_GT(dropped, 0);
  EXPECT_LT(dropped, 7);
  // A 20 ms jitter: offsets of several ms on average (E|N(0, 20)| = 16 ms).
  EXPECT_GT(jitter_sum / 7, 5.0);
  // The same render without motion blur: other frames of front_right, same masks.
  rig["cameras"][1]["sensor"] = nullptr;
  rig["cameras"][2]["sensor"] = nullptr;
  WriteText(dir / "rig.json", rig.dump());
  options.out = dir / "sharp";
  const fs::path sharp = RunRenderJob(options);
  EXPECT_NE(ReadText(seq / "frames/front_right/000003.png"), ReadText(sharp / "frames/front_right/000003.png"));
  EXPECT_EQ(ReadText(seq / "truth/masks/front_right/000003.png"),
            ReadText(sharp / "truth/masks/front_right/000003.png"));
  // The jittered camera saw the (fast) motion at other instants.
  EXPECT_NE(ReadText(seq / "truth/masks/overhead/000003.png"),
            ReadText(sharp / "truth/masks/overhead/000003.png"));
}

INSTANTIATE_TEST_SUITE_P(Backends, DeterminismTest,
                         ::testing::Values(GlBackend::kEgl, GlBackend::kOsMesa),
                         [](const auto& info) { return GlBackendName(info.param); });

}  // namespace
}  // namespace irbench
