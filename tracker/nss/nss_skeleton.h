#pragma once
// Nonlinear spherical shells (thesis 4.4.1, after Chu, Jenkins and Mataric):
// a skeleton of curves with limb labels from one frame's voxel hull.
//
//  1. Isomap: the occupied voxels joined to their 26 neighbours (the graph's
//     edges weighted by the centres' distance), geodesic distances along it
//     by Dijkstra, and classical MDS of them to 3D. The landmark variant (de
//     Silva and Tenenbaum): MDS of the distances among L landmarks picked by
//     farthest-point sampling, every other voxel placed from its distances to
//     the landmarks. In the embedding the limbs are straightened out: a bent
//     arm's voxels lie on a line as long as the arm.
//  2. Spherical shells about the embedding's mean (inside the torso): shell k
//     holds the voxels whose embedded distance from it lies in [k w, (k+1) w).
//  3. Sweep-and-prune in each shell: a box of half-size b about each
//     voxel's embedded point, the boxes sorted along x and every pair that
//     overlaps on all three axes joined; the groups are the shell's clusters.
//     A limb crossing a shell is one cluster, the torso cut by it two.
//  4. A tree: each cluster linked to the cluster one shell in whose voxels
//     its own have the most graph edges to; its root the innermost shell's.
//  5. Shepard interpolation back to the body: a node's world point is the
//     inverse-square-distance-weighted mean (in the embedding, about the
//     cluster's embedded centroid) of its voxels' centres.
//  6. Limbs: the tree's branches from its leaves to the junctions they
//     leave, the shortest pruned; labelled head, arms and legs by where they
//     leave the torso (the junction above the root: head and arms; below:
//     legs), the head as the shortest upper branch, left and right by the
//     branch's side of the body near its junction (`facing` says where the
//     front is).
//
// World frame: metres, z up. Deterministic: no random draws.

#include <Eigen/Core>
#include <filesystem>
#include <string>
#include <vector>

#include "tracker/hull/voxel_hull.h"

namespace irbench {

struct NssOptions {
  int landmarks = 48;           // L-Isomap landmarks (at least 4)
  double shell_width_m = 0.04;  // w: the shells' width in the embedding
  // b: the sweep-and-prune boxes' half-size in the embedding, as a multiple
  // of the voxel size (neighbours lie 1 to 1.7 voxels apart).
  double prune_box_voxels = 1.0;
  int min_cluster_voxels = 4;  // smaller clusters are noise
  double min_branch_m = 0.12;  // shorter branches are pruned
  void Check() const;          // InputError naming the field
};

// One node of the tree: a cluster of one shell.
struct NssNode {
  Eigen::Vector3d p_in_world = Eigen::Vector3d::Zero();      // Shepard-interpolated
  Eigen::Vector3d p_in_embedding = Eigen::Vector3d::Zero();  // the cluster's centroid
  int shell = 0;
  int voxels = 0;
  int parent = -1;  // -1: the root
};

// A labelled skeleton curve, from its junction with the torso to its tip.
struct NssCurve {
  std::string label;  // head, right_arm, left_arm, right_leg, left_leg, torso, or limb (unlabelled)
  std::vector<int> nodes;
  std::vector<Eigen::Vector3d> points_in_world;
  double length_m = 0;  // along the points
};

struct NssSkeleton {
  std::vector<NssNode> nodes;
  std::vector<NssCurve> curves;  // the limbs found, then the torso (upper junction to lower)
  int voxels = 0;                // in the largest connected part of the hull (the others are left out)
  // Per voxel used (world centre) its embedded point: what Isomap made.
  std::vector<Eigen::Vector3d> voxel_centres, embedded;
  const NssCurve* Find(const std::string& label) const;
};

// The skeleton of `hull`'s largest 26-connected part. `facing_xy`: the
// person's front in the world's xy plane (need not be unit). An empty
// skeleton (no nodes) for a hull with fewer voxels than landmarks.
NssSkeleton ComputeNssSkeleton(const VoxelHull& hull, const Eigen::Vector2d& facing_xy, const NssOptions& options = {});

// The curves as a PLY polyline set (ASCII: float x y z and uchar red green
// blue per vertex, one colour per label; an edge between consecutive points
// of a curve), which MeshLab and Blender open; written atomically.
void WriteNssPly(const std::filesystem::path& path, const NssSkeleton& skeleton);

// Geodesic distances (metres along the 26-neighbour graph of `centres`, on
// a grid of `voxel_size_m`) from voxel `from` to every voxel; infinity where
// unconnected. Exposed for tests.
std::vector<double> VoxelGeodesics(const std::vector<Eigen::Vector3i>& cells, double voxel_size_m, int from);

}  // namespace irbench
