#include "tracker/axis/body_parts.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "common/error.h"

namespace irbench {
namespace {

double Median(std::vector<double> values) {
  if (values.empty()) return 0;
  const size_t mid = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + mid, values.end());
  return values[mid];
}

int Find(std::vector<int>& parent, int i) {
  while (parent[i] != i) i = parent[i] = parent[parent[i]];
  return i;
}

// The person: the largest 8-connected blob of a silhouette.
struct LargestBlob {
  cv::Rect sil_box;   // the labelled part of the image (blob_id's pixel (0, 0) is its tl())
  cv::Mat1i blob_id;  // labels within sil_box
  int id = 0;         // the largest blob's label
  // Its extent, in blob_id's pixels (inclusive).
  int left = 0, right = 0, top = 0, bottom = 0;
};

// The largest blob of `silhouette`; nullopt when it is empty or the blob is
// smaller than min_blob_area_px.
std::optional<LargestBlob> FindLargestBlob(const cv::Mat& silhouette,
                                           const BodyPartOptions& options) {
  // Labelled within the silhouette's box (blob_id's pixel (0, 0) is the
  // image's `sil_box.tl()`), with one pass for the areas and boxes
  // (connectedComponentsWithStats takes several times longer in OpenCV 4.6).
  LargestBlob out;
  cv::Rect& sil_box = out.sil_box;
  sil_box = cv::boundingRect(silhouette);
  if (sil_box.empty()) return std::nullopt;
  // OpenCV labels in 2x2 blocks from the image's corner: a box on even rows
  // and columns keeps the blocks, so the blobs are labelled in the whole
  // image's order (which breaks ties between equal areas below).
  sil_box.width += sil_box.x & 1;
  sil_box.x &= ~1;
  sil_box.height += sil_box.y & 1;
  sil_box.y &= ~1;
  cv::Mat1i& blob_id = out.blob_id;
  const int count = cv::connectedComponents(silhouette(sil_box) > 0, blob_id, 8, CV_32S);
  std::vector<int> area(count, 0), left(count, blob_id.cols), right(count, -1), top(count, -1), bottom(count, -1);
  for (int y = 0; y < blob_id.rows; ++y) {
    const int* lp = blob_id[y];
    for (int x = 0; x < blob_id.cols; ++x) {
      const int c = lp[x];
      if (c == 0) continue;
      ++area[c];
      left[c] = std::min(left[c], x);
      right[c] = std::max(right[c], x);
      if (top[c] < 0) top[c] = y;
      bottom[c] = y;
    }
  }
  int best = 0, best_area = 0;
  for (int c = 1; c < count; ++c) {
    if (area[c] > best_area) {
      best_area = area[c];
      best = c;
    }
  }
  if (best == 0 || best_area < options.min_blob_area_px) return std::nullopt;
  out.id = best;
  out.left = left[best];
  out.right = right[best];
  out.top = top[best];
  out.bottom = bottom[best];
  return out;
}

// The largest inscribed circle of the blob.
struct InscribedCircle {
  cv::Point center;  // image pixels
  double radius = 0;
};

// Torso centre: the centre of the blob's largest inscribed circle.
InscribedCircle TorsoCircle(const cv::Mat& silhouette, const LargestBlob& blob) {
  // The distance transform runs on the blob's box with a ring of background
  // around it: the nearest background pixel of any blob pixel lies within, so
  // the values (and the first maximum, row by row) are those of the whole
  // image. (Outside the silhouette's box all is background: the ring there
  // is zeros.)
  const cv::Rect& sil_box = blob.sil_box;
  const cv::Rect box = cv::Rect(sil_box.x + blob.left - 1, sil_box.y + blob.top - 1,
                                blob.right - blob.left + 3, blob.bottom - blob.top + 3) &
                       cv::Rect(0, 0, silhouette.cols, silhouette.rows);
  cv::Mat1b blob_mask = cv::Mat1b::zeros(box.size());
  const cv::Rect labelled = box & sil_box;
  blob_mask(labelled - box.tl()).setTo(255, blob.blob_id(labelled - sil_box.tl()) == blob.id);
  cv::Mat1f inside;
  cv::distanceTransform(blob_mask, inside, cv::DIST_L2, cv::DIST_MASK_PRECISE);
  InscribedCircle out;
  cv::minMaxLoc(inside, nullptr, &out.radius, nullptr, &out.center);
  out.center += box.tl();
  return out;
}

// Is axis point p (its pixel, clamped to the image) on the largest blob?
bool InBlob(const AxisGraph& graph, const LargestBlob& blob, const AxisPoint2d& p) {
  const int u = std::clamp(int(std::floor(p.px.x())), 0, graph.width - 1);
  const int v = std::clamp(int(std::floor(p.px.y())), 0, graph.height - 1);
  return blob.sil_box.contains(cv::Point(u, v)) &&
         blob.blob_id(v - blob.sil_box.y, u - blob.sil_box.x) == blob.id;
}

// Graph point indices, by row.
using RunsByRow = std::map<int, std::vector<int>>;

// The blob's horizontal axis points, grouped by row.
RunsByRow HorizontalRunsByRow(const AxisGraph& graph, const LargestBlob& blob) {
  RunsByRow horizontal_by_row;
  for (size_t i = 0; i < graph.points.size(); ++i) {
    const AxisPoint2d& p = graph.points[i];
    if (p.direction == ScanDirection::kHorizontal && InBlob(graph, blob, p)) {
      horizontal_by_row[p.line].push_back(int(i));
    }
  }
  return horizontal_by_row;
}

// Horizontal axis point of `row` whose run contains column u, or -1.
int RunAt(const AxisGraph& graph, const RunsByRow& horizontal_by_row, int row, double u) {
  auto it = horizontal_by_row.find(row);
  if (it == horizontal_by_row.end()) return -1;
  int nearest = -1;
  double nearest_gap = 1e9;
  for (int i : it->second) {
    const AxisPoint2d& p = graph.points[i];
    const double gap = u < p.t0 ? p.t0 - u : (u > p.t1 ? u - p.t1 : 0.0);
    if (gap < nearest_gap) {
      nearest_gap = gap;
      nearest = i;
    }
  }
  return nearest_gap <= 1.0 ? nearest : -1;
}

// Torso and head runs, the rows they set (head top, torso top, waist, arm
// limit), and the torso's median width and column; labels them in `parts`.
void FindTorsoAndHead(const AxisGraph& graph,
                      const RunsByRow& horizontal_by_row,
                      const InscribedCircle& circle,
                      int blob_bottom,
                      const BodyPartOptions& options,
                      BodyParts2d& parts) {
  const cv::Point& center = circle.center;
  auto run_at = [&](int row, double u) { return RunAt(graph, horizontal_by_row, row, u); };
  // Torso upwards from the centre: thick horizontal runs through its column.
  const double thick = options.torso_min_width_fraction * 2 * circle.radius;
  std::vector<int> torso;
  int row = center.y;
  for (int i; row >= 0 && (i = run_at(row, center.x)) >= 0 && graph.points[i].run_px >= thick; --row) {
    torso.push_back(i);
  }
  parts.torso_top_row = row + 1;
  // Head: the chain of horizontal runs above the torso, following its midpoint.
  double column = center.x;
  row = parts.torso_top_row - 1;
  for (int i; row >= 0 && (i = run_at(row, column)) >= 0; --row) {
    parts.head.push_back(i);
    column = graph.points[i].px.x();
  }
  parts.head_top_row = row + 1;
  std::reverse(parts.head.begin(), parts.head.end());
  const double body_height = std::max(1, blob_bottom - parts.head_top_row);
  parts.waist_row = parts.head_top_row + int(std::lround(0.5 * body_height));
  parts.arm_max_row = parts.head_top_row + int(std::lround(options.arm_max_height_fraction * body_height));
  // Torso downwards to the waist.
  for (int i, r = center.y + 1; r <= parts.waist_row && (i = run_at(r, center.x)) >= 0 &&
                                graph.points[i].run_px >= thick;
       ++r) {
    torso.push_back(i);
  }
  std::sort(torso.begin(), torso.end(),
            [&](int a, int b) { return graph.points[a].line < graph.points[b].line; });
  parts.torso = torso;
  {
    std::vector<double> widths, columns;
    for (int i : torso) {
      widths.push_back(graph.points[i].run_px);
      columns.push_back(graph.points[i].px.x());
    }
    parts.torso_width_px = Median(widths);
    parts.torso_column_px = Median(columns);
  }
  for (int i : parts.torso) parts.labels[i] = BodyPart::kTorso;
  for (int i : parts.head) parts.labels[i] = BodyPart::kHead;
}

// Arm candidates: thin kept points beside the torso, outside the head's runs,
// above the arm limit.
std::vector<int> ArmCandidates(const AxisGraph& graph,
                               const LargestBlob& blob,
                               const BodyPartOptions& options,
                               const BodyParts2d& parts) {
  std::map<int, int> head_by_row;
  for (int i : parts.head) head_by_row[graph.points[i].line] = i;
  const double band = options.torso_band_fraction * parts.torso_width_px;
  std::vector<int> candidates;
  for (size_t i = 0; i < graph.points.size(); ++i) {
    const AxisPoint2d& p = graph.points[i];
    if (!p.kept || parts.labels[i] != BodyPart::kNone || !InBlob(graph, blob, p)) continue;
    if (p.diameter_px > options.arm_max_width_fraction * parts.torso_width_px) continue;
    if (p.px.y() > parts.arm_max_row) continue;
    if (p.px.y() >= parts.torso_top_row && std::abs(p.px.x() - parts.torso_column_px) <= band) continue;
    auto head = head_by_row.find(int(std::lround(p.px.y())));
    if (head != head_by_row.end()) {
      const AxisPoint2d& h = graph.points[head->second];
      if (p.px.x() >= h.t0 - 1 && p.px.x() <= h.t1 + 1) continue;
    }
    candidates.push_back(int(i));
  }
  return candidates;
}

// The arms: the largest component of the candidates on each side of the torso
// column, ordered from the shoulder outwards; labels them in `parts`.
void AssignArms(const AxisGraph& graph,
                const std::vector<int>& candidates,
                const BodyPartOptions& options,
                BodyParts2d& parts) {
  // Components: neighbour links, and links across directions by distance.
  std::vector<int> slot(graph.points.size(), -1);
  for (size_t c = 0; c < candidates.size(); ++c) slot[candidates[c]] = int(c);
  std::vector<int> parent(candidates.size());
  std::iota(parent.begin(), parent.end(), 0);
  auto unite = [&](int a, int b) { parent[Find(parent, a)] = Find(parent, b); };
  const double link2 = options.link_px * options.link_px;
  for (size_t a = 0; a < candidates.size(); ++a) {
    const AxisPoint2d& pa = graph.points[candidates[a]];
    for (int n : pa.neighbors) {
      if (slot[n] >= 0) unite(int(a), slot[n]);
    }
    for (size_t b = a + 1; b < candidates.size(); ++b) {
      const AxisPoint2d& pb = graph.points[candidates[b]];
      if (pb.direction != pa.direction && (pa.px - pb.px).squaredNorm() <= link2) unite(int(a), int(b));
    }
  }
  std::map<int, std::vector<int>> components;
  for (size_t c = 0; c < candidates.size(); ++c) components[Find(parent, int(c))].push_back(candidates[c]);
  std::vector<int>* sides[2] = {&parts.left_arm, &parts.right_arm};
  for (auto& [root, members] : components) {
    if (int(members.size()) < options.min_arm_points) continue;
    double mean_u = 0;
    for (int i : members) mean_u += graph.points[i].px.x();
    mean_u /= double(members.size());
    std::vector<int>& side = *sides[mean_u < parts.torso_column_px ? 0 : 1];
    if (members.size() > side.size()) side = members;
  }
  const Eigen::Vector2d shoulder(parts.torso_column_px, parts.torso_top_row);
  for (int s = 0; s < 2; ++s) {
    std::vector<int>& arm = *sides[s];
    std::sort(arm.begin(), arm.end(), [&](int a, int b) {
      return (graph.points[a].px - shoulder).squaredNorm() < (graph.points[b].px - shoulder).squaredNorm();
    });
    for (int i : arm) parts.labels[i] = s == 0 ? BodyPart::kLeftImageArm : BodyPart::kRightImageArm;
  }
}

}  // namespace

const char* BodyPartName(BodyPart part) {
  switch (part) {
    case BodyPart::kNone: return "none";
    case BodyPart::kHead: return "head";
    case BodyPart::kTorso: return "torso";
    case BodyPart::kLeftImageArm: return "left_image_arm";
    case BodyPart::kRightImageArm: return "right_image_arm";
    case BodyPart::kArm: return "arm";
  }
  return "?";
}

void BodyPartOptions::Check() const {
  auto fraction = [](double v, const char* name) {
    if (!(v > 0 && v <= 1)) throw InputError("", std::string("BodyPartOptions.") + name, "must be in (0, 1]");
  };
  if (min_blob_area_px < 1) throw InputError("", "BodyPartOptions.min_blob_area_px", "must be >= 1");
  fraction(torso_min_width_fraction, "torso_min_width_fraction");
  fraction(arm_max_width_fraction, "arm_max_width_fraction");
  fraction(arm_max_height_fraction, "arm_max_height_fraction");
  fraction(torso_band_fraction, "torso_band_fraction");
  if (!(link_px > 0)) throw InputError("", "BodyPartOptions.link_px", "must be > 0");
  if (min_arm_points < 1) throw InputError("", "BodyPartOptions.min_arm_points", "must be >= 1");
}

std::optional<BodyParts2d> SegmentBodyParts(const cv::Mat& silhouette,
                                            const AxisGraph& graph,
                                            const BodyPartOptions& options) {
  options.Check();
  if (silhouette.empty() || silhouette.type() != CV_8UC1 || silhouette.cols != graph.width ||
      silhouette.rows != graph.height) {
    throw std::invalid_argument("SegmentBodyParts: the silhouette must be CV_8UC1 of the graph's size");
  }
  const std::optional<LargestBlob> blob = FindLargestBlob(silhouette, options);
  if (!blob) return std::nullopt;
  const int blob_bottom = blob->sil_box.y + blob->bottom;
  const InscribedCircle circle = TorsoCircle(silhouette, *blob);

  BodyParts2d parts;
  parts.labels.assign(graph.points.size(), BodyPart::kNone);
  parts.torso_center_px = Eigen::Vector2d(circle.center.x, circle.center.y);
  FindTorsoAndHead(graph, HorizontalRunsByRow(graph, *blob), circle, blob_bottom, options, parts);
  AssignArms(graph, ArmCandidates(graph, *blob, options, parts), options, parts);
  return parts;
}

}  // namespace irbench
