#pragma once
// Datasets out: a rendered sequence in the layouts that learning and motion
// capture tools read (`irbench export`; docs/truth.md, *Dataset exports*).
//
// COCO keypoints (`coco`): OUT/images/<cam>/NNNNNN.png (the frames, hard
// links where the file system allows) and OUT/annotations/person_keypoints.json:
// one image entry per camera frame, one person annotation per camera frame
// whose mask shows the person, with the 17 COCO keypoints mapped from the
// truth's joints2d (the face points, which the truth lacks, are unlabelled),
// COCO visibility 2 (seen), 1 (hidden by the body or the scene), 0 (outside
// the image or unlabelled, at 0, 0), the box and area of the truth mask, and
// the mask itself as uncompressed RLE (column-major runs starting with
// background). Coordinates are the truth's: pixel centres at integers.
//
// EasyMocap (`easymocap`): OUT/images/<cam>/NNNNNN.png, OUT/intri.yml and
// OUT/extri.yml (the sequence's calibration), OUT/annots/<cam>/NNNNNN.json
// (2D keypoints in OpenPose BODY_25 order, confidence 1 seen, 0.5 hidden, 0
// outside or unlabelled) and OUT/keypoints3d/NNNNNN.json (the truth's 3D joints
// in BODY_25 order, world metres, confidence 1 where the truth has the joint).

#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace irbench {

enum class DatasetFormat { kCoco, kEasyMocap };

// "coco" or "easymocap"; nullopt otherwise.
std::optional<DatasetFormat> ParseDatasetFormat(const std::string& name);

struct DatasetExportOptions {
  std::filesystem::path sequence;
  std::filesystem::path out;
  DatasetFormat format = DatasetFormat::kCoco;
  bool overwrite = false;
};

// Writes the export folder (nothing of it is visible until complete) and
// returns it. Throws InputError for a folder that is not a rendered sequence
// (no manifest, calibration or truth), a missing frame or mask (naming the
// file), an output inside the input.
std::filesystem::path RunDatasetExport(const DatasetExportOptions& options);

// The 17 COCO person keypoints in COCO's order, each with the truth joint it
// is taken from ("" for none).
const std::vector<std::pair<std::string, std::string>>& CocoKeypoints();
// The 25 OpenPose BODY_25 keypoints in order, each with the truth joint it is
// taken from ("" for none; "mid_hip" is the mean of the two hips).
const std::vector<std::pair<std::string, std::string>>& Body25Keypoints();

}  // namespace irbench
