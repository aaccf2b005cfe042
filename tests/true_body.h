#pragma once
// The true body of a rendered frame as a closed mesh, for scoring hulls: the
// avatar posed and skinned exactly as the renderer did; volume by signed
// tetrahedra, inside test by ray parity.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "sim/body/avatar.h"
#include "sim/sequence/render_job.h"
#include "tracker/hull/voxel_hull.h"

namespace irbench::testing {

struct BodyMesh {
  std::vector<Eigen::Vector3d> v;
  std::vector<uint32_t> idx;
  Eigen::Vector3d lo, hi;
  // Triangles (first index) by the (y, z) cells of kCell their bounds touch.
  static constexpr double kCell = 0.05;
  int cells_y = 0, cells_z = 0;
  std::vector<std::vector<uint32_t>> buckets;

  int Cell(double value, double lo_value, int count) const {
    return std::clamp(static_cast<int>((value - lo_value) / kCell), 0, count - 1);
  }
  void Bucket() {
    cells_y = static_cast<int>((hi.y() - lo.y()) / kCell) + 1;
    cells_z = static_cast<int>((hi.z() - lo.z()) / kCell) + 1;
    buckets.assign(size_t(cells_y) * cells_z, {});
    for (uint32_t t = 0; t < idx.size(); t += 3) {
      const Eigen::Vector3d &a = v[idx[t]], &b = v[idx[t + 1]], &c = v[idx[t + 2]];
      const int y0 = Cell(std::min({a.y(), b.y(), c.y()}), lo.y(), cells_y);
      const int y1 = Cell(std::max({a.y(), b.y(), c.y()}), lo.y(), cells_y);
      const int z0 = Cell(std::min({a.z(), b.z(), c.z()}), lo.z(), cells_z);
      const int z1 = Cell(std::max({a.z(), b.z(), c.z()}), lo.z(), cells_z);
      for (int z = z0; z <= z1; ++z) {
        for (int y = y0; y <= y1; ++y) buckets[size_t(z) * cells_y + y].push_back(t);
      }
    }
  }
};

// Signed tetrahedra about the origin; the avatar is closed and outward wound.
inline double Volume(const BodyMesh& m) {
  double vol = 0;
  for (size_t t = 0; t < m.idx.size(); t += 3)
    vol += m.v[m.idx[t]].dot(m.v[m.idx[t + 1]].cross(m.v[m.idx[t + 2]]));
  return std::abs(vol) / 6.0;
}

// Ray parity along +x (crossings counted with a half-open rule on the
// triangle's projection onto the y-z plane, so shared edges count once).
inline bool Inside(const BodyMesh& m, const Eigen::Vector3d& p) {
  int crossings = 0;
  const auto& bucket = m.buckets[size_t(m.Cell(p.z(), m.lo.z(), m.cells_z)) * m.cells_y +
                                 m.Cell(p.y(), m.lo.y(), m.cells_y)];
  for (const uint32_t t : bucket) {
    const Eigen::Vector3d& a = m.v[m.idx[t]];
    const Eigen::Vector3d& b = m.v[m.idx[t + 1]];
    const Eigen::Vector3d& c = m.v[m.idx[t + 2]];
    if (std::max({a.x(), b.x(), c.x()}) < p.x()) continue;
    if (std::min({a.y(), b.y(), c.y()}) > p.y() || std::max({a.y(), b.y(), c.y()}) < p.y())
      continue;
    if (std::min({a.z(), b.z(), c.z()}) > p.z() || std::max({a.z(), b.z(), c.z()}) < p.z())
      continue;
    // Barycentric coordinates in the y-z plane.
    const double d = (b.y() - a.y()) * (c.z() - a.z()) - (c.y() - a.y()) * (b.z() - a.z());
    if (std::abs(d) < 1e-18) continue;
    const double w1 = ((p.y() - a.y()) * (c.z() - a.z()) - (c.y() - a.y()) * (p.z() - a.z())) / d;
    const double w2 = ((b.y() - a.y()) * (p.z() - a.z()) - (p.y() - a.y()) * (b.z() - a.z())) / d;
    const double w0 = 1 - w1 - w2;
    if (w0 < 0 || w1 < 0 || w2 < 0) continue;
    const double x = w0 * a.x() + w1 * b.x() + w2 * c.x();
    if (x > p.x()) ++crossings;
  }
  return crossings % 2 == 1;
}

// The avatar of `in` posed at frame `frame` (time frame / fps).
inline BodyMesh PosedBody(const RenderInputs& in, int frame) {
  BodyMesh body;
  const JointTransforms fk = ForwardKinematics(in.avatar.skeleton, in.motion->At(frame / in.fps));
  std::vector<MeshVertex> verts;
  SkinVertices(in.avatar, fk, verts);
  body.idx = in.avatar.indices;
  body.lo.setConstant(1e9);
  body.hi.setConstant(-1e9);
  for (const MeshVertex& v : verts) {
    body.v.push_back(v.position.cast<double>());
    body.lo = body.lo.cwiseMin(body.v.back());
    body.hi = body.hi.cwiseMax(body.v.back());
  }
  body.Bucket();
  return body;
}

// The posed body's voxels at `voxel_m`: centres inside the mesh.
inline VoxelHull Voxelise(const BodyMesh& body, double voxel_m) {
  VoxelHull hull;
  hull.voxel_size_m = voxel_m;
  hull.origin_m = body.lo - Eigen::Vector3d::Constant(2 * voxel_m);
  const Eigen::Vector3d extent = body.hi - body.lo + Eigen::Vector3d::Constant(4 * voxel_m);
  hull.nx = static_cast<int>(std::ceil(extent.x() / voxel_m));
  hull.ny = static_cast<int>(std::ceil(extent.y() / voxel_m));
  hull.nz = static_cast<int>(std::ceil(extent.z() / voxel_m));
  hull.occupied.assign(size_t(hull.nx) * hull.ny * hull.nz, 0);
  for (int z = 0; z < hull.nz; ++z) {
    for (int y = 0; y < hull.ny; ++y) {
      for (int x = 0; x < hull.nx; ++x) {
        if (Inside(body, hull.VoxelCenter(x, y, z))) {
          hull.occupied[hull.Index(x, y, z)] = 1;
          ++hull.occupied_count;
        }
      }
    }
  }
  return hull;
}

}  // namespace irbench::testing
