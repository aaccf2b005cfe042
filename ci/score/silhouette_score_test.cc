// The silhouette scorer on masks whose counts are known by construction:
// rectangles shifted and grown by whole pixels, a mask cut at the image's
// border, and folders of masks with an empty truth, a missing silhouette and
// bad images.

#include "ci/score/silhouette_score.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "common/error.h"
#include "tests/test_util.h"

namespace irbench {
namespace {
namespace fs = std::filesystem;

cv::Mat Rect(cv::Size size, cv::Rect r) {
  cv::Mat m = cv::Mat::zeros(size, CV_8U);
  m(r).setTo(255);
  return m;
}

TEST(CountSilhouetteTest, AShiftByOnePixelIsAllNearTheOutline) {
  const cv::Mat truth = Rect({64, 48}, {10, 10, 20, 10});
  const SilhouetteCounts c = CountSilhouette(truth, Rect({64, 48}, {11, 10, 20, 10}));
  EXPECT_EQ(c.truth, 200);
  EXPECT_EQ(c.silhouette, 200);
  EXPECT_EQ(c.false_near, 10);  // column 30
  EXPECT_EQ(c.false_far, 0);
  EXPECT_EQ(c.missed_near, 10);  // column 10
  EXPECT_EQ(c.missed_far, 0);
  EXPECT_DOUBLE_EQ(c.iou(), 190.0 / 210.0);
  EXPECT_DOUBLE_EQ(CountSilhouette(truth, truth).iou(), 1.0);
}

TEST(CountSilhouetteTest, GrownByThreePixelsOnlyTheFirstRingIsNear) {
  const cv::Mat truth = Rect({64, 48}, {10, 10, 20, 10});
  const SilhouetteCounts c = CountSilhouette(truth, Rect({64, 48}, {7, 7, 26, 16}));
  EXPECT_EQ(c.false_near, 22 * 12 - 20 * 10);  // the 8-neighbours, corners included
  EXPECT_EQ(c.false_far, 26 * 16 - 22 * 12);
  EXPECT_EQ(c.missed_near + c.missed_far, 0);
  // A blob far from the body is all far; a hole in the body is far, unless on the outline.
  cv::Mat sil = truth.clone();
  sil(cv::Rect(50, 30, 4, 5)).setTo(255);
  sil(cv::Rect(15, 13, 3, 2)).setTo(0);
  sil.at<uint8_t>(10, 20) = 0;  // on the top edge
  const SilhouetteCounts d = CountSilhouette(truth, sil);
  EXPECT_EQ(d.false_far, 20);
  EXPECT_EQ(d.false_near, 0);
  EXPECT_EQ(d.missed_far, 6);
  EXPECT_EQ(d.missed_near, 1);
}

TEST(CountSilhouetteTest, BeyondTheImageIsOutsideTheBody) {
  // A body cut by the left border: its pixels in column 0 are on the outline.
  const cv::Mat truth = Rect({20, 20}, {0, 0, 5, 10});
  const SilhouetteCounts left = CountSilhouette(truth, Rect({20, 20}, {1, 0, 4, 10}));
  EXPECT_EQ(left.missed_near, 10);
  EXPECT_EQ(left.missed_far, 0);
  // Column 2 lost: rows 1-8 are deep inside; row 0 touches the top border and
  // row 9 the background below.
  cv::Mat sil = truth.clone();
  sil.col(2).setTo(0);
  const SilhouetteCounts middle = CountSilhouette(truth, sil);
  EXPECT_EQ(middle.missed_far, 8);
  EXPECT_EQ(middle.missed_near, 2);
}

class SilhouetteFolderTest : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = irbench::testing::FreshTempDir("silhouette_score_" + std::to_string(::getpid())); }
  void TearDown() override { fs::remove_all(dir_); }
  void Put(const std::string& what, const std::string& camera, int frame, const cv::Mat& m) {
    char name[32];
    std::snprintf(name, sizeof(name), "%06d.png", frame);
    fs::create_directories(dir_ / what / camera);
    ASSERT_TRUE(cv::imwrite((dir_ / what / camera / name).string(), m));
  }
  fs::path dir_;
};

TEST_F(SilhouetteFolderTest, SummariesOverCamerasAndFrames) {
  const cv::Size size(64, 48);
  const cv::Mat body = Rect(size, {10, 10, 20, 10});
  // Camera "a": IoUs 1, 190/210 (shifted) and 200/264 (grown by a pixel all round).
  Put("masks", "a", 0, body);
  Put("sil", "a", 0, body);
  Put("masks", "a", 1, body);
  Put("sil", "a", 1, Rect(size, {11, 10, 20, 10}));
  Put("masks", "a", 2, body);
  Put("sil", "a", 2, Rect(size, {9, 9, 22, 12}));
  // Camera "b": one frame with the person, one without (5 false pixels), one
  // with no silhouette written.
  Put("masks", "b", 0, body);
  Put("sil", "b", 0, body);
  Put("masks", "b", 1, cv::Mat::zeros(size, CV_8U));
  Put("sil", "b", 1, Rect(size, {0, 0, 5, 1}));
  Put("masks", "b", 2, body);
  const SilhouetteScore s = ScoreSilhouettes(dir_ / "masks", dir_ / "sil");
  ASSERT_EQ(s.frames.size(), 4u);
  EXPECT_EQ(s.empty_frames, 1);
  EXPECT_EQ(s.empty_false, 5);
  EXPECT_EQ(s.missing, 1);
  EXPECT_EQ(s.frames[1].camera, "a");
  EXPECT_EQ(s.frames[1].frame, 1);
  const SilhouetteSummary all = s.All();
  EXPECT_EQ(all.camera_frames, 4);
  // Sorted: 200/264, 190/210, 1, 1; the median is the upper middle one.
  EXPECT_DOUBLE_EQ(all.iou_median, 1.0);
  EXPECT_DOUBLE_EQ(all.iou_p10, 200.0 / 264.0);
  EXPECT_DOUBLE_EQ(all.iou_min, 200.0 / 264.0);
  EXPECT_DOUBLE_EQ(all.false_share, (10.0 + 64.0) / 800.0);
  EXPECT_DOUBLE_EQ(all.missed_share, 10.0 / 800.0);
  ASSERT_TRUE(all.near_outline_share);
  EXPECT_DOUBLE_EQ(*all.near_outline_share, 1.0);
  const auto by_camera = s.ByCamera();
  EXPECT_EQ(by_camera.at("a").camera_frames, 3);
  EXPECT_DOUBLE_EQ(by_camera.at("a").iou_median, 190.0 / 210.0);
  EXPECT_DOUBLE_EQ(by_camera.at("b").iou_median, 1.0);
  EXPECT_FALSE(by_camera.at("b").near_outline_share);  // no errors at all: no share
  const nlohmann::json j = s.ToJson();
  EXPECT_DOUBLE_EQ(j["iou_median"].get<double>(), 1.0);
  EXPECT_EQ(j["cameras"]["a"]["camera_frames"], 3);
  EXPECT_EQ(j["empty_false_pixels"], 5);
  EXPECT_EQ(j["missing"], 1);
  const std::string md = s.Markdown();
  EXPECT_NE(md.find("| a | 3 | 0.905 | 0.758 | 12.3% | 1.7% | 100% |"), std::string::npos) << md;
  EXPECT_NE(md.find("| All | 4 | 1.000 |"), std::string::npos) << md;
  EXPECT_NE(md.find("| b | 1 | 1.000 | 1.000 | 0.0% | 0.0% | – |"), std::string::npos) << md;
  EXPECT_TRUE(j["cameras"]["b"]["near_outline_share"].is_null());
  EXPECT_NE(md.find("1 camera-frames without the person in view: 5 silhouette pixels"), std::string::npos) << md;
  const std::string csv = s.Csv();
  EXPECT_NE(csv.find("a,1,200,200,0.904762,10,0,10,0\n"), std::string::npos) << csv;
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 5);  // header and four camera-frames
}

// Twenty camera-frames of known IoU (k/20 of a 20-pixel bar found, k = 1..20,
// written in shuffled order and with unpadded names): the tenth percentile is
// the second smallest (nearest rank), the median the eleventh, and the frames
// come out by number.
TEST_F(SilhouetteFolderTest, PercentilesByRankAndFramesByNumber) {
  const cv::Size size(40, 10);
  const cv::Mat bar = Rect(size, {0, 0, 20, 1});
  for (const int k : {7, 20, 1, 13, 2, 9, 16, 4, 11, 18, 3, 14, 6, 19, 10, 5, 17, 8, 15, 12}) {
    const std::string name = std::to_string(k);  // 1.png ... 20.png
    fs::create_directories(dir_ / "masks/c");
    fs::create_directories(dir_ / "sil/c");
    ASSERT_TRUE(cv::imwrite((dir_ / "masks/c" / (name + ".png")).string(), bar));
    ASSERT_TRUE(cv::imwrite((dir_ / "sil/c" / (name + ".png")).string(), Rect(size, {0, 0, k, 1})));
  }
  const SilhouetteScore s = ScoreSilhouettes(dir_ / "masks", dir_ / "sil");
  ASSERT_EQ(s.frames.size(), 20u);
  for (size_t i = 0; i < s.frames.size(); ++i) {
    EXPECT_EQ(s.frames[i].frame, int(i) + 1);
    EXPECT_DOUBLE_EQ(s.frames[i].iou(), (i + 1) / 20.0);
  }
  const SilhouetteSummary all = s.All();
  EXPECT_DOUBLE_EQ(all.iou_p10, 2 / 20.0);
  EXPECT_DOUBLE_EQ(all.iou_median, 11 / 20.0);
  EXPECT_DOUBLE_EQ(all.iou_min, 1 / 20.0);
}

TEST_F(SilhouetteFolderTest, BadImagesNameTheFile) {
  const cv::Size size(64, 48);
  Put("masks", "a", 0, Rect(size, {10, 10, 20, 10}));
  Put("sil", "a", 0, Rect({32, 24}, {5, 5, 10, 5}));
  try {
    ScoreSilhouettes(dir_ / "masks", dir_ / "sil");
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), (dir_ / "sil/a/000000.png").string());
    EXPECT_NE(e.message().find("32x24, the truth mask 64x48"), std::string::npos) << e.what();
  }
  irbench::testing::WriteText(dir_ / "sil/a/000000.png", "not a png");
  try {
    ScoreSilhouettes(dir_ / "masks", dir_ / "sil");
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), (dir_ / "sil/a/000000.png").string());
    EXPECT_EQ(e.message(), "unreadable image");
  }
  // A truth mask whose name is no frame number, with or without a silhouette.
  Put("masks", "a", 0, Rect(size, {10, 10, 20, 10}));
  Put("sil", "a", 0, Rect(size, {10, 10, 20, 10}));
  ASSERT_TRUE(cv::imwrite((dir_ / "masks/a/000001_old.png").string(), Rect(size, {10, 10, 20, 10})));
  try {
    ScoreSilhouettes(dir_ / "masks", dir_ / "sil");
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), (dir_ / "masks/a/000001_old.png").string());
    EXPECT_NE(e.message().find("not a frame number"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace irbench
