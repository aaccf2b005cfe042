#pragma once
// Voxel occupancy (thesis 4.2, Fig. 4.4): the stage volume is divided into a
// voxel grid; a look-up table, computed once per rig and grid, maps every voxel
// to the sub-pixel projection x of its centre in every camera and a radius r
// there. A voxel is occupied when, in every camera that sees it, a silhouette
// pixel centre lies within r of x: the camera's distance transform of the
// silhouette (distance to the nearest silhouette pixel centre, bilinearly
// interpolated at x) is at most r. World frame: metres, z up, floor z = 0.
//
// r = footprint_scale * R + margin_px, where R is the largest distance from x
// to a projected corner of the voxel. With footprint_scale = 1 the disk holds
// the voxel's whole projection, so a voxel that holds any point of the true
// body is kept as long as every silhouette covers the body's projection to
// within margin_px: conservative, but the hull grows by a shell of about R +
// margin_px. Smaller scales trade a little containment for a tighter hull
// (measured in hull_closed_loop_test). Cameras for which the disk is partly
// outside the image, or the voxel partly behind the camera, place no
// constraint on the voxel.

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <opencv2/core.hpp>
#include <optional>
#include <vector>

#include "geometry/camera.h"

namespace irbench {

struct VoxelGridOptions {
  // The carving box, world metres (default: the stage volume).
  Eigen::Vector3d min_corner_m{-1.5, -1.5, 0.0};
  Eigen::Vector3d max_corner_m{1.5, 1.5, 2.2};
  double voxel_size_m = 0.02;
  // The radius tested around the voxel centre's projection: footprint_scale
  // times the projected corner radius plus margin_px (pixels; 0.5 would also
  // cover the half pixel between a mask's pixel centres and its outline).
  // Measured on theater4 with 4 cameras (hull_closed_loop_test with
  // IRBENCH_HULL_SWEEP=1; share of the true body inside, volume / body's):
  //   2 cm, scale 1, margin 0 (default): 99.3-99.7%, 1.5-1.8x;
  //   2.5 cm, scale 1, margin 0: 99.8%, 1.7-2.1x (over 2x for the slim p4);
  //   2.5 cm, scale 0.5, margin 0.5: 99.5-99.7%, 1.6-1.9x;
  //   scale 0, margin 0 (centre only, the plain visual hull): 78-87%, 1.0x.
  double footprint_scale = 1.0;
  double margin_px = 0.0;
  // Voxels whose centre fewer cameras see are never occupied (the corners of
  // the box that no camera sees would otherwise all be kept).
  int min_observing_cameras = 2;
  // Corners nearer than this to a camera's image plane (camera z, metres)
  // make that camera place no constraint on the voxel.
  double near_m = 0.05;
  // Views allowed to disagree: a voxel is carved only when more than this many
  // of the cameras that see it put it outside their silhouettes. 0 is the
  // thesis's hull; 1 keeps body parts one camera's silhouette lost (clothing
  // as grey as the wall), at the cost of volume.
  int max_missing_views = 0;

  void Check() const;  // throws InputError naming the field
};

// The result of one carving.
struct VoxelHull {
  Eigen::Vector3d origin_m = Eigen::Vector3d::Zero();  // min corner of voxel (0,0,0)
  double voxel_size_m = 0.0;
  int nx = 0, ny = 0, nz = 0;
  std::vector<uint8_t> occupied;  // 0/1, index (z * ny + y) * nx + x
  int occupied_count = 0;
  // When set, every occupied voxel lies within this box of voxel indices,
  // {x0, y0, z0, x1, y1, z1}, each range [lo, hi): a bound the carver knows
  // from its blocks, so that OccupiedCenters need not read the whole grid.
  std::optional<std::array<int, 6>> occupied_within;

  size_t Index(int x, int y, int z) const { return (size_t(z) * ny + y) * nx + x; }
  bool Occupied(int x, int y, int z) const { return occupied[Index(x, y, z)] != 0; }
  // Is world point `p_in_world` inside an occupied voxel? False outside the grid.
  bool ContainsPoint(const Eigen::Vector3d& p_in_world) const;
  Eigen::Vector3d VoxelCenter(int x, int y, int z) const;
  // Occupied volume, cubic metres.
  double VolumeM3() const;
  // World centres of the occupied voxels, metres.
  std::vector<Eigen::Vector3d> OccupiedCenters() const;
};

// Per pixel centre, the exact Euclidean distance in pixels to the nearest
// pixel centre of `silhouette` (CV_8UC1, > 127 is silhouette), CV_32F and
// continuous; 1e6 everywhere when the silhouette is empty.
cv::Mat DistanceToSilhouette(const cv::Mat& silhouette);

// Precomputes the voxel-to-pixel table for one rig and grid (thesis 4.2: "the
// camera calibration parameters allow us to pre-compute a look-up table"), then
// carves any number of silhouette sets with it.
class VoxelCarver {
 public:
  // Throws InputError for bad options or no cameras. Cost: about two
  // projections per voxel and camera (0.6 s for 4 cameras and 2.5 cm voxels);
  // memory: 8 bytes per candidate voxel and camera plus 4 per candidate, and
  // the bounds of the blocks, sub-blocks and cells (about 2.5 + 1.5 per camera
  // bytes per candidate).
  VoxelCarver(std::vector<Camera> cameras, const VoxelGridOptions& options = {});

  // `silhouettes[c]`: CV_8UC1 of camera c's size, > 127 is silhouette.
  // Throws InputError on a count or size mismatch.
  //
  // Coarse to fine: the candidates are grouped in blocks of kBlock^3 voxels,
  // and the look-up table holds, per block and camera, a bound on the test
  // values of all the block's voxels from the distance transform at one pixel
  // (the transform is 1-Lipschitz). A block that more than max_missing_views
  // cameras certainly carve is skipped; a camera that certainly keeps a block
  // is not consulted for its voxels. A block some camera is unsure of is
  // judged again, in those cameras, by its octants' bounds (sub-blocks of
  // (kBlock/2)^3 voxels), and those by theirs (cells of 2^3); only the rest
  // go through the per-voxel test. The result is bit-identical to
  // CarveReference().
  VoxelHull Carve(const std::vector<cv::Mat>& silhouettes) const;

  // The same from the silhouettes' distance transforms (DistanceToSilhouette
  // per camera), for a caller that needs them too: the transform is the
  // carving's largest cost. Throws InputError on a count, size or type
  // mismatch. The blocks are carved in parallel; the result does not depend
  // on the thread count.
  VoxelHull CarveDistances(const std::vector<cv::Mat>& distances) const;
  // DistanceToSilhouette of each camera's silhouette, as Carve takes them;
  // throws InputError on a count or size mismatch.
  std::vector<cv::Mat> DistanceTransforms(const std::vector<cv::Mat>& silhouettes) const;

  // The same occupancy by the plain evaluation of every candidate voxel in
  // every camera, without the block bounds: the reference for tests; slow.
  VoxelHull CarveReference(const std::vector<cv::Mat>& silhouettes) const;

  const VoxelGridOptions& options() const { return options_; }
  const std::vector<Camera>& cameras() const { return cameras_; }
  int nx() const { return nx_; }
  int ny() const { return ny_; }
  int nz() const { return nz_; }
  // Voxels that enough cameras observe (the only ones ever occupied).
  size_t candidate_count() const { return candidates_.size(); }

 private:
  // Edge of a block, in voxels (a sub-block's is half, a cell's a quarter).
  static constexpr int kBlock = 8;

  // Per candidate voxel and camera: the index of the pixel at the floor of the
  // centre's projection x, the fractional part of x in 1/256 pixel, and the
  // radius in 1/64 pixel; pixel < 0: no constraint.
  struct Footprint {
    int32_t pixel;
    uint8_t frac_u, frac_v;
    uint16_t radius_q;
  };
  // Per block and camera, with D the camera's distance transform: every voxel
  // of the block fails the test when D[pixel] > carve_above, and passes it
  // when D[pixel] <= keep_below (carve_above = +inf, keep_below = -inf: no
  // such certainty).
  struct BlockBound {
    int32_t pixel;
    float carve_above, keep_below;
  };
  // The candidates [first, first + count) in candidates_ form one block
  // (or sub-block, or cell); a block's sub-blocks are sub_blocks_[sub_first,
  // sub_first + sub_count), and a sub-block's cells cells_[the same].
  struct Block {
    uint32_t first, count;
    uint32_t sub_first, sub_count;
    uint32_t index;  // (z_block * by + y_block) * bx + x_block in the grid of blocks (blocks only)
  };

  VoxelHull EmptyHull() const;

  // Constructor steps, in order.
  // World centre of voxel index v ((z * ny + y) * nx + x), metres.
  Eigen::Vector3d VoxelCentre(size_t v) const;
  // Pass 1: per voxel, how many cameras see its centre (in front, in the image).
  std::vector<uint8_t> CountObservingCameras() const;
  // Fills candidates_, blocks_, sub_blocks_ and cells_ from the counts of pass 1.
  void GroupCandidates(const std::vector<uint8_t>& observed);
  // Pass 2: footprints_, every candidate's footprint in every camera.
  void ComputeFootprints();
  // The bound of `block`'s candidates in camera c (from footprints_).
  BlockBound BoundOf(const Block& block, size_t c) const;
  // Fills bounds_, sub_bounds_ and cell_bounds_.
  void ComputeBounds();

  std::vector<Camera> cameras_;
  VoxelGridOptions options_;
  int nx_ = 0, ny_ = 0, nz_ = 0;
  std::vector<uint32_t> candidates_;    // voxel indices, grouped by block
  std::vector<Footprint> footprints_;   // candidate-major: [candidate][camera]
  std::vector<Block> blocks_;           // the blocks holding candidates
  std::vector<BlockBound> bounds_;      // [block][camera]
  std::vector<Block> sub_blocks_;       // the blocks' octants holding candidates
  std::vector<BlockBound> sub_bounds_;  // [sub-block][camera]
  std::vector<Block> cells_;            // the sub-blocks' octants (2x2x2 voxels) holding candidates
  std::vector<BlockBound> cell_bounds_;  // [cell][camera]
};

}  // namespace irbench
