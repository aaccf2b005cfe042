// Datasets out (issue 33.3): a rendered sequence exported as COCO keypoints
// and as EasyMocap's layout, checked by a checker written from the COCO
// format's description and against the truth and the calibration as OpenCV
// reads them back.

#include "sim/sequence/dataset_export.h"

#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <set>

#include "common/error.h"
#include "sim/sequence/render_job.h"
#include "tests/test_util.h"
#include "tests/track_figures.h"

namespace irbench {
namespace {
namespace fs = std::filesystem;
using irbench::testing::ReadJsonLines;
using nlohmann::json;
using irbench::testing::FreshTempDir;
using irbench::testing::WriteText;

json ReadJson(const fs::path& path) {
  std::ifstream in(path);
  return json::parse(in);
}

class DatasetExportTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new fs::path(FreshTempDir("dataset_export_" + std::to_string(getpid())));
    WriteText(*dir_ / "fast.json", irbench::testing::FastMotionJson());
    RenderJobOptions options;
    options.rig = "lab4";
    options.avatar = "p2";
    options.motion = (*dir_ / "fast.json").string();
    options.frames = 4;
    options.background_frames = 0;
    options.supersample = 1;
    options.out = *dir_ / "seq";
    seq_ = new fs::path(RunRenderJob(options));
  }
  static void TearDownTestSuite() {
    fs::remove_all(*dir_);
    delete dir_;
    delete seq_;
  }
  static fs::path* dir_;
  static fs::path* seq_;
};
fs::path* DatasetExportTest::dir_ = nullptr;
fs::path* DatasetExportTest::seq_ = nullptr;

// COCO's RLE decoded (column-major runs, background first).
cv::Mat DecodeRle(const json& rle) {
  const int h = rle["size"][0], w = rle["size"][1];
  cv::Mat mask = cv::Mat::zeros(h, w, CV_8U);
  long at = 0;
  bool on = false;
  for (const auto& count : rle["counts"]) {
    for (long k = 0; k < count.get<long>(); ++k, ++at) {
      if (on && at < static_cast<long>(h) * w) mask.at<uint8_t>(static_cast<int>(at % h), static_cast<int>(at / h)) = 255;
    }
    on = !on;
  }
  EXPECT_EQ(at, static_cast<long>(h) * w);
  return mask;
}

TEST_F(DatasetExportTest, CocoKeypointsPassTheFormatsRulesAndHoldTheTruth) {
  DatasetExportOptions options;
  options.sequence = *seq_;
  options.out = *dir_ / "coco";
  options.format = DatasetFormat::kCoco;
  const fs::path out = RunDatasetExport(options);
  const json coco = ReadJson(out / "annotations" / "person_keypoints.json");
  const std::vector<json> truth = ReadJsonLines(*seq_ / "truth/frames.jsonl");

  // Categories: one person category with 17 named keypoints and a skeleton
  // over them (1-based).
  ASSERT_EQ(coco["categories"].size(), 1u);
  const json& person = coco["categories"][0];
  EXPECT_EQ(person["name"], "person");
  ASSERT_EQ(person["keypoints"].size(), 17u);
  for (const auto& edge : person["skeleton"]) {
    for (const auto& k : edge) EXPECT_TRUE(k.get<int>() >= 1 && k.get<int>() <= 17);
  }
  // Images: unique ids, files that exist and have the stated size.
  std::map<int, json> images;
  for (const auto& image : coco["images"]) {
    const int id = image["id"];
    EXPECT_TRUE(images.emplace(id, image).second) << "duplicate image id " << id;
    const cv::Mat pixels = cv::imread((out / "images" / image["file_name"].get<std::string>()).string(), cv::IMREAD_UNCHANGED);
    ASSERT_FALSE(pixels.empty()) << image["file_name"];
    EXPECT_EQ(pixels.cols, image["width"].get<int>());
    EXPECT_EQ(pixels.rows, image["height"].get<int>());
  }
  EXPECT_EQ(images.size(), 4u * 4u);  // 4 cameras x 4 frames
  // Annotations: unique ids, an existing image, 17 x 3 values, visibility in
  // {0, 1, 2} with unlabelled points at 0, 0, num_keypoints the labelled
  // count, the box inside the image, the area the mask's pixel count, the RLE
  // the mask; the keypoints equal the truth's joints2d.
  std::set<int> ids;
  int annotations = 0;
  for (const auto& a : coco["annotations"]) {
    ++annotations;
    EXPECT_TRUE(ids.insert(a["id"].get<int>()).second);
    ASSERT_TRUE(images.count(a["image_id"].get<int>()));
    const json& image = images[a["image_id"].get<int>()];
    EXPECT_EQ(a["category_id"], 1);
    ASSERT_EQ(a["keypoints"].size(), 51u);
    int labelled = 0;
    for (int k = 0; k < 17; ++k) {
      const double x = a["keypoints"][3 * k], y = a["keypoints"][3 * k + 1];
      const int v = a["keypoints"][3 * k + 2];
      EXPECT_TRUE(v == 0 || v == 1 || v == 2);
      if (v == 0) {
        EXPECT_TRUE(x == 0 && y == 0);
      }
      labelled += v > 0;
    }
    EXPECT_EQ(a["num_keypoints"].get<int>(), labelled);
    const double bx = a["bbox"][0], by = a["bbox"][1], bw = a["bbox"][2], bh = a["bbox"][3];
    EXPECT_TRUE(bx >= 0 && by >= 0 && bw > 0 && bh > 0 && bx + bw <= image["width"].get<int>() &&
                by + bh <= image["height"].get<int>());
    const std::string cam = image["irbench_camera"];
    const int frame = image["irbench_frame"];
    char name[32];
    std::snprintf(name, sizeof(name), "%06d.png", frame);
    const cv::Mat mask = cv::imread((*seq_ / "truth/masks" / cam / name).string(), cv::IMREAD_GRAYSCALE);
    EXPECT_EQ(a["area"].get<int>(), cv::countNonZero(mask));
    EXPECT_EQ(cv::countNonZero(DecodeRle(a["segmentation"]) != (mask > 0)), 0);
    const json& joints = truth.at(frame)["joints2d"][cam];
    for (int k = 0; k < 17; ++k) {
      const std::string ours = CocoKeypoints()[k].second;
      if (ours.empty()) {
        EXPECT_EQ(a["keypoints"][3 * k + 2], 0);
        continue;
      }
      const json& p = joints[ours];
      EXPECT_EQ(a["keypoints"][3 * k + 2].get<int>(), p[2].get<int>()) << ours;
      if (p[2].get<int>() > 0) {
        EXPECT_DOUBLE_EQ(a["keypoints"][3 * k].get<double>(), p[0].get<double>()) << ours;
        EXPECT_DOUBLE_EQ(a["keypoints"][3 * k + 1].get<double>(), p[1].get<double>()) << ours;
      }
    }
  }
  EXPECT_GE(annotations, 12);  // the person is in (nearly) every view
  // The same sequence gives the same bytes.
  options.out = *dir_ / "coco2";
  RunDatasetExport(options);
  std::ifstream a(out / "annotations/person_keypoints.json"), b(*dir_ / "coco2/annotations/person_keypoints.json");
  EXPECT_EQ(std::string(std::istreambuf_iterator<char>(a), {}), std::string(std::istreambuf_iterator<char>(b), {}));
}

TEST_F(DatasetExportTest, EasyMocapReadsBackThroughOpenCvWithTheSameCameras) {
  DatasetExportOptions options;
  options.sequence = *seq_;
  options.out = *dir_ / "easymocap";
  options.format = DatasetFormat::kEasyMocap;
  const fs::path out = RunDatasetExport(options);
  const std::vector<json> truth = ReadJsonLines(*seq_ / "truth/frames.jsonl");

  cv::FileStorage intri((out / "intri.yml").string(), cv::FileStorage::READ);
  cv::FileStorage extri((out / "extri.yml").string(), cv::FileStorage::READ);
  ASSERT_TRUE(intri.isOpened() && extri.isOpened());
  std::vector<std::string> names;
  intri["names"] >> names;
  ASSERT_EQ(names.size(), 4u);
  for (const std::string& cam : names) {
    // Against the sequence's own files, read by OpenCV too.
    cv::FileStorage own_intri((*seq_ / "calib/intri.yml").string(), cv::FileStorage::READ);
    cv::FileStorage own_extri((*seq_ / "calib/extri.yml").string(), cv::FileStorage::READ);
    for (const auto& [file, own, key] : {std::tuple{&intri, &own_intri, "K_"}, std::tuple{&intri, &own_intri, "dist_"},
                                         std::tuple{&extri, &own_extri, "Rot_"}, std::tuple{&extri, &own_extri, "T_"}}) {
      cv::Mat mine, theirs;
      (*file)[key + cam] >> mine;
      (*own)[key + cam] >> theirs;
      ASSERT_FALSE(mine.empty()) << key << cam;
      EXPECT_EQ(cv::norm(mine, theirs, cv::NORM_INF), 0.0) << key << cam;
    }
  }
  // 2D annotations in BODY_25 order equal the truth's joints2d; 3D keypoints
  // its joints3d.
  for (int frame = 0; frame < 4; ++frame) {
    char name[32];
    std::snprintf(name, sizeof(name), "%06d.json", frame);
    for (const std::string& cam : names) {
      const json annot = ReadJson(out / "annots" / cam / name);
      EXPECT_TRUE(fs::exists(out / annot["filename"].get<std::string>()));
      if (annot["annots"].empty()) continue;
      const json& keypoints = annot["annots"][0]["keypoints"];
      ASSERT_EQ(keypoints.size(), 25u);
      for (int k = 0; k < 25; ++k) {
        const std::string ours = Body25Keypoints()[k].second;
        if (ours.empty() || ours == "mid_hip") continue;
        const json& p = truth.at(frame)["joints2d"][cam][ours];
        const double c = keypoints[k][2];
        EXPECT_EQ(c, p[2] == 2 ? 1.0 : p[2] == 1 ? 0.5 : 0.0) << ours;
        if (c > 0) {
          EXPECT_DOUBLE_EQ(keypoints[k][0].get<double>(), p[0].get<double>()) << ours;
        }
      }
    }
    const json people = ReadJson(out / "keypoints3d" / name);
    ASSERT_EQ(people.size(), 1u);
    const json& k3 = people[0]["keypoints3d"];
    ASSERT_EQ(k3.size(), 25u);
    const json& joints = truth.at(frame)["joints3d"];
    EXPECT_DOUBLE_EQ(k3[4][0].get<double>(), joints["right_wrist"][0].get<double>());
    EXPECT_DOUBLE_EQ(k3[8][2].get<double>(),
                     0.5 * (joints["left_hip"][2].get<double>() + joints["right_hip"][2].get<double>()));
    EXPECT_EQ(k3[0][3], 0.0);  // no nose in the truth
  }
}

TEST_F(DatasetExportTest, BadInputIsOneErrorAndNothingWritten) {
  DatasetExportOptions options;
  options.format = DatasetFormat::kCoco;
  options.sequence = *dir_ / "nowhere";
  options.out = *dir_ / "bad";
  try {
    RunDatasetExport(options);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("manifest.json"), std::string::npos) << e.what();
  }
  // Into the sequence itself: refused.
  options.sequence = *seq_;
  options.out = *seq_ / "coco";
  EXPECT_THROW(RunDatasetExport(options), InputError);
  EXPECT_FALSE(fs::exists(*seq_ / "coco"));
  EXPECT_FALSE(fs::exists(*dir_ / "bad"));
  EXPECT_EQ(ParseDatasetFormat("yolo"), std::nullopt);
  // A mask missing from a copy of the sequence: the error names it.
  const fs::path copy = *dir_ / "seq_copy";
  fs::copy(*seq_, copy, fs::copy_options::recursive);
  const fs::directory_entry camera_masks = *fs::directory_iterator(copy / "truth/masks");
  fs::remove(camera_masks.path() / "000002.png");
  options.sequence = copy;
  options.out = *dir_ / "bad";
  try {
    RunDatasetExport(options);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(e.file().find("000002.png"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(*dir_ / "bad"));
}

}  // namespace
}  // namespace irbench
