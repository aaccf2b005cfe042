#pragma once
// The shape descriptor of thesis 4.3 (Fig. 4.5, Eqs. 4.1-4.2): surface points
// of the visual hull seen from reference points on a cylinder about the body,
// each relative position binned in spherical coordinates (r, theta, phi) in
// the reference point's own frame, the histograms of all reference points
// summed and divided by their largest bin.
//
// What the thesis leaves open, and what is chosen here (docs/recognition.md):
// - The points: the centres of the voxel hull's surface voxels (occupied, with
//   an empty face neighbour), the voxel hull's stand-in for the thesis's
//   samples of the polyhedral hull's surface, taken at most `max_points` of
//   them by an even stride so that the cost is bounded.
// - The cylinder: its axis vertical through the points' centroid, from the
//   floor (z = 0) to the user's height h, radius 0.5 h (half the arm span, so
//   it bounds the arms held out); the cylinder scales with h and not with the
//   hull's extent, so raising an arm does not shrink the rest of the shape.
// - The reference points: `rings` heights at (i + 1/2) h / rings and
//   `azimuths` evenly spaced angles, on the cylinder's surface.
// - A reference point's frame: n the outward normal, t the tangent
//   (counter-clockwise seen from above), z up. For a point P: d = P - Q;
//   r = |d| / diag, diag = sqrt((2R)^2 + h^2) the cylinder's largest chord,
//   clamped to [0, 1]; theta = the angle from z, [0, pi]; phi = atan2(d.t,
//   d.n), [-pi, pi). Each into equal bins.
// - Smoothing: the summed histogram is blurred by a Gaussian of
//   `smoothing_bins` bins (standard deviation) along each of r, theta (the
//   edges absorb what falls off) and phi (circular), kernel cut at 3 bins,
//   before the normalisation. 24 bins a side resolve postures, but a
//   broader or taller person shifts an arm's mass by a bin, and an
//   unsmoothed histogram then shares little with the atoms learned on
//   others (measured: docs/recognition.md).
// - Facing: summing over the azimuths makes the descriptor invariant to turns
//   about the vertical axis by multiples of 360/azimuths degrees (and nearly
//   so between), so no facing is needed. The thesis notes the consequence: a
//   left and a right arm in the same posture have about the same descriptor.

#include <Eigen/Core>
#include <vector>

#include "tracker/hull/voxel_hull.h"

namespace irbench {

struct ShapeDescriptorOptions {
  int rings = 3;        // reference heights (thesis 5.3: 3)
  int azimuths = 16;    // reference points per height (thesis 5.3: 16)
  int r_bins = 24;      // thesis 5.3: 24 x 24 x 24
  int theta_bins = 24;
  int phi_bins = 24;
  double radius_per_height = 0.5;  // cylinder radius / user height
  int max_points = 1500;           // surface points used, at most
  double smoothing_bins = 1.0;     // Gaussian blur of the histogram, bins; 0: none

  int bin_count() const { return r_bins * theta_bins * phi_bins; }
  void Check() const;  // throws InputError naming the field
};

// The descriptor: bin (k, l, p) of r, theta, phi at index (k * L + l) * P + p.
struct ShapeDescriptor {
  std::vector<float> bins;  // normalised: the largest is 1 (all 0 for no points)
  int point_count = 0;      // surface points binned
  Eigen::Vector2d axis_xy = Eigen::Vector2d::Zero();  // the cylinder's axis, world metres
  double height_m = 0;

  int NonEmptyBins() const;
};

// The surface voxels' centres of `hull` (world metres), in index order.
std::vector<Eigen::Vector3d> HullSurfacePoints(const VoxelHull& hull);

// The descriptor of surface points `points_in_world` (metres, z up, floor
// z = 0) for a user of height `height_m` (> 0; std::invalid_argument else).
ShapeDescriptor ComputeShapeDescriptor(const std::vector<Eigen::Vector3d>& points_in_world, double height_m,
                                       const ShapeDescriptorOptions& options = {});

// Of a hull: its surface points, then ComputeShapeDescriptor.
ShapeDescriptor HullShapeDescriptor(const VoxelHull& hull, double height_m,
                                       const ShapeDescriptorOptions& options = {});

}  // namespace irbench
