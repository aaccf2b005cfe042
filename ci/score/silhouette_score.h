#pragma once
// The tracker's silhouettes against the truth masks (issue 6's bar: the
// median IoU over camera-frames). Besides the IoU, each camera-frame's errors
// are split by where they lie: within one pixel of the true outline (an
// 8-neighbour of a pixel on the other side of it) or farther. At 320x240 a
// one-pixel ring round a body is a sixth to a quarter of its area (more seen
// from overhead), so the split tells an outline that is a pixel off (blur,
// dark rims) from what is wrong (shadows, lost limbs).

#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace irbench {

// Pixel counts of one camera-frame whose truth mask holds the person.
struct SilhouetteCounts {
  std::string camera;
  int frame = 0;
  long truth = 0;          // true body pixels
  long silhouette = 0;     // the tracker's silhouette pixels
  long false_near = 0;     // silhouette outside the body, touching it (8-neighbour)
  long false_far = 0;      // silhouette outside the body, farther
  long missed_near = 0;    // body outside the silhouette, on the true outline
  long missed_far = 0;     // body outside the silhouette, deeper inside
  long intersection() const { return truth - missed_near - missed_far; }
  double iou() const;
};

// A summary over camera-frames (one camera's, or all of them).
struct SilhouetteSummary {
  int camera_frames = 0;
  double iou_median = 0;  // the middle one (the upper of the two for an even count)
  double iou_p10 = 0;     // the tenth percentile (nearest rank): the bad frames
  double iou_min = 0;
  // Sums over the camera-frames, as a share of the true body's pixels.
  double false_share = 0;
  double missed_share = 0;
  // Of all false and missed pixels, the share within one pixel of the true
  // outline; nullopt when there are none.
  std::optional<double> near_outline_share;
};

struct SilhouetteScore {
  std::filesystem::path silhouettes;     // the folder scored
  std::vector<SilhouetteCounts> frames;  // by camera name, then frame number
  // Camera-frames whose truth mask is empty (the person out of view): not in
  // the IoU; the silhouette pixels found there are false foreground.
  int empty_frames = 0;
  long empty_false = 0;
  // Camera-frames with a truth mask but no silhouette image (a track of fewer frames).
  int missing = 0;

  SilhouetteSummary All() const;
  std::map<std::string, SilhouetteSummary> ByCamera() const;
  nlohmann::json ToJson() const;
  std::string Markdown() const;  // the table of tables.md
  std::string Csv() const;       // silhouettes.csv: one row per camera-frame
};

// Counts of one camera-frame; both masks CV_8UC1 of one size, nonzero = in.
// Pixels beyond the image count as outside the body.
SilhouetteCounts CountSilhouette(const cv::Mat& truth, const cv::Mat& silhouette);

// Scores `silhouettes`/<camera>/<frame>.png (irbench track's) against
// `masks`/<camera>/<frame>.png (the sequence's truth/masks; frame names are
// digits only, 000123.png). Throws InputError naming the file for a truth
// mask whose name is no frame number, an unreadable image, or one of another
// size than its truth mask. Logs a warning when no truth mask has a
// silhouette (another tracker's names?).
SilhouetteScore ScoreSilhouettes(const std::filesystem::path& masks, const std::filesystem::path& silhouettes);

}  // namespace irbench
