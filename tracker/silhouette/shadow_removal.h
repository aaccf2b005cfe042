#pragma once
// Edge-based shadow removal (thesis 3.1, Fig. 3.1). The stage is lit by light
// diffused off the screen, so shadows have blurry edges while the body's
// outline is sharp:
//  1. Canny edges of each frame; the empty-stage edges are "trained" as a
//     per-pixel edge rate over the background frames.
//  2. A frame's edge pixels where the background rarely has one (within a
//     pixel) are the segmented edges; they are dilated to close gaps.
//  3. Silhouette pixels are scanned along horizontal, vertical and both
//     diagonal lines: a pixel is body when, along enough directions, it lies
//     between two segmented edge pixels of its own silhouette run; else shadow.

#include <opencv2/core.hpp>
#include <optional>
#include <vector>

namespace irbench {

struct ShadowOptions {
  double blur_sigma = 1.0;     // px, Gaussian before Canny (grain)
  double canny_low = 6;        // Canny hysteresis thresholds (8-bit grey, 3x3 Sobel, L2):
  double canny_high = 15;      // low, for the washed-out thesis images
  double background_edge_rate = 0.25;  // a pixel is a background edge above this rate
  int edge_dilate = 1;                 // px at 320x240: closes gaps in the outline
  // A run end counts as enclosed when a segmented edge lies within this many
  // pixels of it (at 320x240) inside the run.
  int edge_reach = 2;
  // How many of the four scan directions must enclose a pixel (1..4).
  int min_directions = 1;
  void Check() const;  // throws InputError naming the field
};

class ShadowRemover {
 public:
  // nullopt when `background` is empty or sizes differ.
  static std::optional<ShadowRemover> Train(const std::vector<cv::Mat>& background, const ShadowOptions& options);

  // The frame's edges (CV_8U 0/255) not in the background, dilated, inside the
  // silhouette dilated by the reach.
  cv::Mat SegmentedEdges(const cv::Mat& frame, const cv::Mat& silhouette) const;
  // The silhouette with the shadow pixels removed. A shadow only darkens: when
  // `darker` (255 where the frame is darker than the empty stage; read only
  // within the silhouette's box) is given, silhouette pixels outside it are
  // body whatever the edges say.
  cv::Mat Remove(const cv::Mat& frame, const cv::Mat& silhouette, const cv::Mat& darker = cv::Mat()) const;

  const cv::Mat& background_edges() const { return background_edges_; }

 private:
  cv::Mat Edges(const cv::Mat& frame) const;
  // On a region of the image: `scale` is the full image's width / 320.
  cv::Mat SegmentedEdges(const cv::Mat& frame, const cv::Mat& silhouette, const cv::Mat& background_edges,
                         double scale) const;

  ShadowOptions options_;
  cv::Mat background_edges_;  // CV_8U 0/255
};

// Step 3 alone: keeps silhouette pixels enclosed by `edges` along at least
// `min_directions` of the four scan directions; `reach` as in ShadowOptions.
cv::Mat KeepEnclosed(const cv::Mat& silhouette, const cv::Mat& edges, int min_directions, int reach);

}  // namespace irbench
