#include "sim/sequence/dataset_export.h"

#include <map>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "common/atomic_file.h"
#include "common/cancel.h"
#include "common/error.h"
#include "common/logging.h"
#include "sequence_format/calibration.h"
#include "sequence_format/frame_lines.h"
#include "sequence_format/manifest.h"
#include "sim/sequence/render_resume.h"  // FrameFileName

namespace irbench {
namespace fs = std::filesystem;
using nlohmann::json;

namespace {

// The frame's image, linked (or copied) into `to`. Throws InputError when missing.
void LinkImage(const fs::path& from, const fs::path& to) {
  if (!fs::is_regular_file(from)) throw InputError(from.string(), "file", "missing");
  std::error_code ec;
  fs::create_hard_link(from, to, ec);
  if (ec) fs::copy_file(from, to);
}

cv::Mat ReadMask(const fs::path& file) {
  if (!fs::is_regular_file(file)) throw InputError(file.string(), "file", "missing (the truth's person mask)");
  cv::Mat mask = cv::imread(file.string(), cv::IMREAD_GRAYSCALE);
  if (mask.empty()) throw InputError(file.string(), "file", "not a readable image");
  return mask;
}

// COCO's uncompressed RLE of a mask: run lengths in column-major order,
// starting with a (possibly empty) run of background.
json Rle(const cv::Mat& mask) {
  std::vector<int> counts;
  bool current = false;
  int run = 0;
  for (int x = 0; x < mask.cols; ++x) {
    for (int y = 0; y < mask.rows; ++y) {
      const bool on = mask.at<uint8_t>(y, x) != 0;
      if (on != current) {
        counts.push_back(run);
        run = 0;
        current = on;
      }
      ++run;
    }
  }
  counts.push_back(run);
  return {{"counts", counts}, {"size", {mask.rows, mask.cols}}};
}

// The three numbers of a truth joint: [u, v, visibility] in a camera's
// joints2d, [x, y, z] in joints3d; nullopt when absent.
std::optional<std::array<double, 3>> JointEntry(const json& joints, const std::string& joint) {
  const auto it = joints.find(joint);
  if (it == joints.end() || !it->is_array() || it->size() != 3) return std::nullopt;
  return std::array<double, 3>{(*it)[0].get<double>(), (*it)[1].get<double>(), (*it)[2].get<double>()};
}

// BODY_25's mid hip: the mean of the two hips, seen only when both are.
std::optional<std::array<double, 3>> Body25Joint2d(const json& camera_joints, const std::string& joint) {
  if (joint != "mid_hip") return JointEntry(camera_joints, joint);
  const auto l = JointEntry(camera_joints, "left_hip"), r = JointEntry(camera_joints, "right_hip");
  if (!l || !r) return std::nullopt;
  return std::array<double, 3>{0.5 * ((*l)[0] + (*r)[0]), 0.5 * ((*l)[1] + (*r)[1]), std::min((*l)[2], (*r)[2])};
}

std::optional<std::array<double, 3>> Body25Joint3d(const json& joints, const std::string& joint) {
  if (joint != "mid_hip") return JointEntry(joints, joint);
  const auto l = JointEntry(joints, "left_hip"), r = JointEntry(joints, "right_hip");
  if (!l || !r) return std::nullopt;
  return std::array<double, 3>{0.5 * ((*l)[0] + (*r)[0]), 0.5 * ((*l)[1] + (*r)[1]), 0.5 * ((*l)[2] + (*r)[2])};
}

struct Source {
  Calibration calibration;
  Manifest manifest;
  std::map<int, json> truth;

  // Frame `f`'s truth line; InputError when the truth lacks it.
  const json& TruthLine(const fs::path& seq, int f) const {
    const auto line = truth.find(f);
    if (line == truth.end()) {
      throw InputError((seq / "truth/frames.jsonl").string(), "frame " + std::to_string(f), "missing");
    }
    return line->second;
  }
};

void ExportCoco(const Source& src, const fs::path& seq, const fs::path& out) {
  json images = json::array(), annotations = json::array();
  fs::create_directories(out / "annotations");
  int image_id = 0, annotation_id = 0;
  for (const Camera& cam : src.calibration.cameras) {
    fs::create_directories(out / "images" / cam.name);
    for (int f = 0; f < src.manifest.frame_count; ++f) {
      ThrowIfCancelled();
      const std::string name = FrameFileName(f, "png");
      LinkImage(seq / "frames" / cam.name / name, out / "images" / cam.name / name);
      ++image_id;
      images.push_back({{"id", image_id},
                        {"file_name", cam.name + "/" + name},
                        {"width", cam.width},
                        {"height", cam.height},
                        {"irbench_camera", cam.name},
                        {"irbench_frame", f}});
      const json& line = src.TruthLine(seq, f);
      const cv::Mat mask = ReadMask(seq / "truth" / "masks" / cam.name / name);
      const int area = cv::countNonZero(mask);
      if (area == 0) continue;  // the person is not in this view
      const cv::Rect box = cv::boundingRect(mask);
      const json& camera_joints = line["joints2d"][cam.name];
      json keypoints = json::array();
      int labelled = 0;
      for (const auto& [coco, ours] : CocoKeypoints()) {
        const auto p = ours.empty() ? std::nullopt : JointEntry(camera_joints, ours);
        const int v = p ? static_cast<int>((*p)[2]) : 0;
        if (v > 0) {
          keypoints.push_back((*p)[0]), keypoints.push_back((*p)[1]), keypoints.push_back(v);
          ++labelled;
        } else {
          keypoints.push_back(0), keypoints.push_back(0), keypoints.push_back(0);
        }
      }
      ++annotation_id;
      annotations.push_back({{"id", annotation_id},
                             {"image_id", image_id},
                             {"category_id", 1},
                             {"iscrowd", 0},
                             {"keypoints", keypoints},
                             {"num_keypoints", labelled},
                             {"bbox", {box.x, box.y, box.width, box.height}},
                             {"area", area},
                             {"segmentation", Rle(mask)}});
    }
  }
  json names = json::array();
  for (const auto& [coco, ours] : CocoKeypoints()) names.push_back(coco);
  // COCO's person skeleton (1-based keypoint indices).
  const json skeleton = {{16, 14}, {14, 12}, {17, 15}, {15, 13}, {12, 13}, {6, 12}, {7, 13},
                         {6, 7},   {6, 8},   {7, 9},   {8, 10},  {9, 11},  {2, 3},  {1, 2},
                         {1, 3},   {2, 4},   {3, 5},   {4, 6},   {5, 7}};
  const json coco = {
      {"info",
       {{"description", "irbench sequence rendered with exact truth (docs/truth.md, Dataset exports)"},
        {"irbench_sequence", fs::absolute(seq).lexically_normal().string()},
        {"irbench_manifest", {{"scene", src.manifest.scene}, {"rig", src.manifest.rig},
                              {"avatar", src.manifest.avatar}, {"motion", src.manifest.motion},
                              {"sensor", src.manifest.sensor}, {"seed", src.manifest.seed}}}}},
      {"licenses", json::array()},
      {"images", images},
      {"annotations", annotations},
      {"categories",
       {{{"id", 1}, {"name", "person"}, {"supercategory", "person"}, {"keypoints", names}, {"skeleton", skeleton}}}}};
  AtomicWriteFile(out / "annotations" / "person_keypoints.json", coco.dump() + "\n");
  Log().info("export coco: {} images, {} person annotations", images.size(), annotations.size());
}

void ExportEasyMocap(const Source& src, const fs::path& seq, const fs::path& out) {
  AtomicWriteFile(out / "intri.yml", IntriYaml(src.calibration.cameras));
  AtomicWriteFile(out / "extri.yml", ExtriYaml(src.calibration.cameras));
  fs::create_directories(out / "keypoints3d");
  for (const Camera& cam : src.calibration.cameras) {
    fs::create_directories(out / "images" / cam.name);
    fs::create_directories(out / "annots" / cam.name);
  }
  for (int f = 0; f < src.manifest.frame_count; ++f) {
    ThrowIfCancelled();
    const json& line = src.TruthLine(seq, f);
    const std::string name = FrameFileName(f, "png");
    for (const Camera& cam : src.calibration.cameras) {
      LinkImage(seq / "frames" / cam.name / name, out / "images" / cam.name / name);
      const cv::Mat mask = ReadMask(seq / "truth" / "masks" / cam.name / name);
      json people = json::array();
      if (cv::countNonZero(mask) > 0) {
        const cv::Rect box = cv::boundingRect(mask);
        const json& camera_joints = line["joints2d"][cam.name];
        json keypoints = json::array();
        for (const auto& [body25, ours] : Body25Keypoints()) {
          const auto p = ours.empty() ? std::nullopt : Body25Joint2d(camera_joints, ours);
          const int v = p ? static_cast<int>((*p)[2]) : 0;
          if (v > 0) {
            keypoints.push_back({(*p)[0], (*p)[1], v == 2 ? 1.0 : 0.5});
          } else {
            keypoints.push_back({0.0, 0.0, 0.0});
          }
        }
        people.push_back({{"personID", 0},
                          {"bbox", {box.x, box.y, box.x + box.width - 1, box.y + box.height - 1, 1.0}},
                          {"keypoints", keypoints},
                          {"isKeyframe", false}});
      }
      const json annot = {{"filename", "images/" + cam.name + "/" + name},
                          {"height", cam.height},
                          {"width", cam.width},
                          {"annots", people},
                          {"isKeyframe", false}};
      AtomicWriteFile(out / "annots" / cam.name / FrameFileName(f, "json"), annot.dump() + "\n");
    }
    json keypoints = json::array();
    for (const auto& [body25, ours] : Body25Keypoints()) {
      const auto p = ours.empty() ? std::nullopt : Body25Joint3d(line["joints3d"], ours);
      keypoints.push_back(p ? json{(*p)[0], (*p)[1], (*p)[2], 1.0} : json{0.0, 0.0, 0.0, 0.0});
    }
    const json people = json::array({{{"id", 0}, {"keypoints3d", keypoints}}});
    AtomicWriteFile(out / "keypoints3d" / FrameFileName(f, "json"), people.dump() + "\n");
  }
  Log().info("export easymocap: {} frames x {} cameras", src.manifest.frame_count, src.calibration.cameras.size());
}

}  // namespace

std::optional<DatasetFormat> ParseDatasetFormat(const std::string& name) {
  if (name == "coco") return DatasetFormat::kCoco;
  if (name == "easymocap") return DatasetFormat::kEasyMocap;
  return std::nullopt;
}

const std::vector<std::pair<std::string, std::string>>& CocoKeypoints() {
  static const std::vector<std::pair<std::string, std::string>> keypoints = {
      {"nose", ""},
      {"left_eye", ""},
      {"right_eye", ""},
      {"left_ear", ""},
      {"right_ear", ""},
      {"left_shoulder", "left_shoulder"},
      {"right_shoulder", "right_shoulder"},
      {"left_elbow", "left_elbow"},
      {"right_elbow", "right_elbow"},
      {"left_wrist", "left_wrist"},
      {"right_wrist", "right_wrist"},
      {"left_hip", "left_hip"},
      {"right_hip", "right_hip"},
      {"left_knee", "left_knee"},
      {"right_knee", "right_knee"},
      {"left_ankle", "left_ankle"},
      {"right_ankle", "right_ankle"}};
  return keypoints;
}

const std::vector<std::pair<std::string, std::string>>& Body25Keypoints() {
  static const std::vector<std::pair<std::string, std::string>> keypoints = {
      {"Nose", ""},          {"Neck", "neck"},          {"RShoulder", "right_shoulder"},
      {"RElbow", "right_elbow"}, {"RWrist", "right_wrist"}, {"LShoulder", "left_shoulder"},
      {"LElbow", "left_elbow"},  {"LWrist", "left_wrist"},  {"MidHip", "mid_hip"},
      {"RHip", "right_hip"},     {"RKnee", "right_knee"},   {"RAnkle", "right_ankle"},
      {"LHip", "left_hip"},      {"LKnee", "left_knee"},    {"LAnkle", "left_ankle"},
      {"REye", ""},          {"LEye", ""},              {"REar", ""},
      {"LEar", ""},          {"LBigToe", ""},           {"LSmallToe", ""},
      {"LHeel", ""},         {"RBigToe", ""},           {"RSmallToe", ""},
      {"RHeel", ""}};
  return keypoints;
}

fs::path RunDatasetExport(const DatasetExportOptions& options) {
  if (options.out.empty()) throw InputError("", "--out", "must not be empty");
  if (!HasManifest(options.sequence)) {
    throw InputError((options.sequence / kManifestFile).string(), "file",
                     "missing: not a rendered sequence folder (irbench render writes one)");
  }
  Source src;
  src.manifest = ReadManifest(options.sequence);
  src.calibration = ReadCalibration(options.sequence);
  src.truth = ReadFrameLines(options.sequence / "truth" / "frames.jsonl");
  CheckOutputApart(options.out, {options.sequence}, "--out");
  StagingDir staging(options.out, options.overwrite, "--out", "export");
  if (options.format == DatasetFormat::kCoco) {
    ExportCoco(src, options.sequence, staging.path());
  } else {
    ExportEasyMocap(src, options.sequence, staging.path());
  }
  staging.Commit();
  return staging.final_path();
}

}  // namespace irbench
