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
  fs::remove(bad / "frames" / first_cam / "000002.png");
  try {
    SequenceInput::Open(bad);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("'" + first_cam + "' has 2 and 2"), std::string::npos) << e.what();
  }
  // A gap with later frames behind it is not the end of the sequence.
  fs::copy_file(bad / "frames" / first_cam / "000001.png", bad / "frames" / first_cam / "000002.png");
  fs::remove(bad / "frames" / first_cam / "000001.png");
  try {
    SequenceInput::Open(bad);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("000001.png is missing while later frames exist"), std::string::npos)
        << e.what();
  }
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
