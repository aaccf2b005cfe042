#include "tracker/io/sequence_input.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include "common/error.h"
#include "sim/sequence/render_job.h"
#include "tests/test_util.h"

namespace irbench {
namespace {
namespace fs = std::filesystem;

class SequenceInputTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    // ctest runs each test in its own process, maybe at once: a folder per process.
    dir_ = irbench::testing::FreshTempDir("tracker_io_" + std::to_string(::getpid()));
    RenderJobOptions options;
    options.rig = "lab4";
    options.frames = 3;
    options.background_frames = 2;
    options.out = dir_ / "seq";
    RunRenderJob(options);
  }
  static void TearDownTestSuite() { fs::remove_all(dir_); }
  static fs::path dir_;
};
fs::path SequenceInputTest::dir_;

// The calibration read back through OpenCV's FileStorage reproduces every
// truth pixel the renderer wrote (the test reads the truth; the tracker never).
TEST_F(SequenceInputTest, CalibrationReproducesTheTruthPixels) {
  const SequenceInput in = SequenceInput::Open(dir_ / "seq");
  ASSERT_EQ(in.cameras().size(), 4u);
  EXPECT_EQ(in.frame_count(), 3);
  EXPECT_EQ(in.background_count(), 2);
  std::ifstream truth(dir_ / "seq/truth/frames.jsonl");
  std::string line;
  int checked = 0;
  while (std::getline(truth, line)) {
    const auto frame = nlohmann::json::parse(line);
    for (const Camera& cam : in.cameras()) {
      for (const auto& [joint, p] : frame["joints3d"].items()) {
        const auto uv = frame["joints2d"][cam.name][joint];
        if (uv[2] == 0) continue;
        const Eigen::Vector2d px = cam.Project(Eigen::Vector3d(p[0], p[1], p[2]));
        EXPECT_NEAR(px.x(), double(uv[0]), 1e-3) << cam.name << " " << joint;
        EXPECT_NEAR(px.y(), double(uv[1]), 1e-3) << cam.name << " " << joint;
        ++checked;
      }
    }
  }
  EXPECT_GT(checked, 100);
  const cv::Mat f = in.Frame(2, 1), b = in.Background(3, 1);
  EXPECT_EQ(f.type(), CV_8UC1);
  EXPECT_EQ(f.cols, in.cameras()[2].width);
  EXPECT_EQ(b.rows, in.cameras()[3].height);
  EXPECT_EQ(in.Backgrounds(0).size(), 2u);
  // A frame-set: every camera's frame, in the cameras' order.
  const std::vector<cv::Mat> set = in.FrameSet(1);
  ASSERT_EQ(set.size(), in.cameras().size());
  for (size_t c = 0; c < set.size(); ++c) {
    EXPECT_EQ(cv::norm(set[c], in.Frame(static_cast<int>(c), 1), cv::NORM_INF), 0) << in.cameras()[c].name;
  }
  EXPECT_NE(cv::norm(set[0], in.Frame(0, 0), cv::NORM_INF), 0);  // frame 1, not 0: the person moved
}

TEST_F(SequenceInputTest, BadFoldersNameTheFile) {
  const fs::path bad = dir_ / "bad";
  fs::remove_all(bad);
  fs::copy(dir_ / "seq", bad, fs::copy_options::recursive);
  const std::string first_cam = SequenceInput::Open(bad).cameras()[0].name;
  // A rig that lost frames: the sequence still opens, runs to the last frame
  // of any camera, and says what is missing (issue 27: degrade, don't stop).
  fs::remove(bad / "frames" / first_cam / "000002.png");
  {
    const SequenceInput lost = SequenceInput::Open(bad);
    EXPECT_EQ(lost.frame_count(), 3);
    EXPECT_EQ(lost.MissingFrames()[0], 1);
    EXPECT_EQ(lost.MissingFrames()[1], 0);
    std::vector<std::string> problems;
    const std::vector<cv::Mat> set = lost.TryFrameSet(2, &problems);
    EXPECT_TRUE(set[0].empty());
    EXPECT_NE(problems[0].find("000002.png: missing"), std::string::npos) << problems[0];
    EXPECT_FALSE(set[1].empty());
    EXPECT_TRUE(problems[1].empty());
    EXPECT_THROW(lost.FrameSet(2), InputError);  // the strict reader still refuses
  }
  // A gap with later frames behind it, and an undecodable file.
  fs::copy_file(bad / "frames" / first_cam / "000001.png", bad / "frames" / first_cam / "000002.png");
  fs::remove(bad / "frames" / first_cam / "000001.png");
  irbench::testing::WriteText(bad / "frames" / first_cam / "000000.png", "\x89PNG truncated");
  {
    const SequenceInput lost = SequenceInput::Open(bad);
    EXPECT_EQ(lost.MissingFrames()[0], 1);
    std::vector<std::string> problems;
    EXPECT_TRUE(lost.TryFrameSet(1, &problems)[0].empty());
    EXPECT_TRUE(lost.TryFrameSet(0, &problems)[0].empty());
    EXPECT_NE(problems[0].find("000000.png"), std::string::npos) << problems[0];
    EXPECT_FALSE(lost.TryFrameSet(2, &problems)[0].empty());
  }
  // A stray far-off number is not a sequence of lost frames.
  fs::copy_file(bad / "frames" / first_cam / "000002.png", bad / "frames" / first_cam / "000900.png");
  EXPECT_THROW(SequenceInput::Open(bad), InputError);
  fs::remove(bad / "frames" / first_cam / "000900.png");
  // A calibration rotation that is not one.
  {
    const fs::path skew = dir_ / "skew";
    fs::remove_all(skew);
    fs::copy(dir_ / "seq", skew, fs::copy_options::recursive);
    std::string extri = irbench::testing::ReadText(skew / "calib/extri.yml");
    const size_t at = extri.find("Rot_" + first_cam);
    const size_t data = extri.find_first_not_of(' ', extri.find("data: [", at) + 7);
    extri.replace(data, extri.find(',', data) - data, "0.5");  // R(0,0) = 0.5: no longer orthonormal
    irbench::testing::WriteText(skew / "calib/extri.yml", extri);
    try {
      SequenceInput::Open(skew);
      ADD_FAILURE() << "no error";
    } catch (const InputError& e) {
      EXPECT_EQ(e.field(), "Rot_" + first_cam) << e.what();
    }
  }
  std::ofstream(bad / "calib/extri.yml") << "%YAML:1.0\nnames: [a]\n";
  try {
    SequenceInput::Open(bad);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(fs::path(e.file()).filename(), "extri.yml") << e.what();
    EXPECT_EQ(e.field(), "Rot_" + first_cam) << e.what();
  }
  EXPECT_THROW(SequenceInput::Open(dir_ / "nothing"), InputError);
}

}  // namespace
}  // namespace irbench
