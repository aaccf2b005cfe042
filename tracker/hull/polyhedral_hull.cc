#include "tracker/hull/polyhedral_hull.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <functional>
#include <string>

#include "common/error.h"

namespace irbench {
namespace {

// A polygon edge in a view's undistorted normalised image plane.
struct Edge {
  Eigen::Vector3d line;  // homogeneous line through p and q
  Eigen::Vector2d p, q;
};

// One view as the other views' rays see it.
struct View {
  const Camera* camera = nullptr;
  Eigen::Matrix3d cam_from_world_rotation;
  Eigen::Vector3d cam_from_world_translation;
  std::vector<Edge> edges;   // polygon edges (all loops)
  std::vector<Edge> border;  // image border (where the camera stops constraining)
  std::vector<std::vector<Eigen::Vector2d>> loops;  // undistorted, for even-odd
};

Eigen::Vector2d Normalised(const Camera& cam, const Eigen::Vector2d& px) {
  const Eigen::Vector2d xd((px.x() - cam.cx) / cam.fx, (px.y() - cam.cy) / cam.fy);
  return cam.Undistort(xd).value_or(xd);
}

Edge MakeEdge(const Eigen::Vector2d& p, const Eigen::Vector2d& q) {
  return {Eigen::Vector3d(p.x(), p.y(), 1).cross(Eigen::Vector3d(q.x(), q.y(), 1)), p, q};
}

bool EvenOdd(const std::vector<std::vector<Eigen::Vector2d>>& loops, const Eigen::Vector2d& x) {
  bool inside = false;
  for (const auto& v : loops) {
    for (size_t i = 0, j = v.size() - 1; i < v.size(); j = i++) {
      if ((v[i].y() > x.y()) != (v[j].y() > x.y())) {
        const double cx =
            v[j].x() + (x.y() - v[j].y()) * (v[i].x() - v[j].x()) / (v[i].y() - v[j].y());
        if (x.x() < cx) inside = !inside;
      }
    }
  }
  return inside;
}

// Ray parameters where the ray C + s d crosses `edges` in view `v`
// (h(s) = a + s b is the point in the view's camera frame).
void Crossings(const std::vector<Edge>& edges,
               const Eigen::Vector3d& a,
               const Eigen::Vector3d& b,
               double near_m,
               double s0,
               double s1,
               std::vector<double>& out) {
  for (const Edge& e : edges) {
    const double den = e.line.dot(b);
    if (std::abs(den) < 1e-15) continue;
    const double s = -e.line.dot(a) / den;
    if (!(s > s0 && s < s1)) continue;
    const Eigen::Vector3d h = a + s * b;
    if (h.z() <= near_m) continue;
    const Eigen::Vector2d x = h.head<2>() / h.z();
    const Eigen::Vector2d pq = e.q - e.p;
    const double lambda = (x - e.p).dot(pq) / pq.squaredNorm();
    if (lambda >= -1e-9 && lambda <= 1 + 1e-9) out.push_back(s);
  }
}

// Does view `v` allow world point `x`? Only points in front of the camera that
// project inside its image are constrained.
bool Allows(const View& v, const Eigen::Vector3d& x, double near_m) {
  const Eigen::Vector3d h = v.cam_from_world_rotation * x + v.cam_from_world_translation;
  if (h.z() <= near_m) return true;
  const Eigen::Vector2d px = v.camera->Project(x);
  if (px.x() < -0.5 || px.y() < -0.5 || px.x() > v.camera->width - 0.5 ||
      px.y() > v.camera->height - 0.5)
    return true;
  return EvenOdd(v.loops, h.head<2>() / h.z());
}

// Slab clip of the ray to the box; false when it misses.
bool ClipToBox(const Eigen::Vector3d& c,
               const Eigen::Vector3d& d,
               const Eigen::Vector3d& lo,
               const Eigen::Vector3d& hi,
               double& s0,
               double& s1) {
  s0 = 0;
  s1 = 1e9;
  for (int k = 0; k < 3; ++k) {
    if (std::abs(d[k]) < 1e-15) {
      if (c[k] < lo[k] || c[k] > hi[k]) return false;
      continue;
    }
    double t0 = (lo[k] - c[k]) / d[k], t1 = (hi[k] - c[k]) / d[k];
    if (t0 > t1) std::swap(t0, t1);
    s0 = std::max(s0, t0);
    s1 = std::min(s1, t1);
  }
  return s1 > s0;
}

struct Interval {
  double lo, hi;
};

// One ray of a wedge: its direction and its intervals inside all other cones
// (ray parameter = distance from the camera centre, metres), with the mesh
// vertex of each interval end once made (-1: not yet).
struct RaySample {
  Eigen::Vector3d dir = Eigen::Vector3d::Zero();
  std::vector<Interval> intervals;
  std::vector<int64_t> ids;
};

}  // namespace

void PolyhedralHullOptions::Check() const {
  for (int a = 0; a < 3; ++a) {
    if (!(max_corner_m[a] > min_corner_m[a]))
      throw InputError("", "max_corner_m", "must exceed min_corner_m on every axis");
  }
  if (!(ray_step_px > 0)) throw InputError("", "ray_step_px", "must be > 0");
  if (max_rays_per_edge < 1) throw InputError("", "max_rays_per_edge", "must be >= 1");
  if (!(near_m > 0)) throw InputError("", "near_m", "must be > 0");
  if (!(max_chord_error_m > 0)) throw InputError("", "max_chord_error_m", "must be > 0");
  if (max_refinement < 0 || max_refinement > 20)
    throw InputError("", "max_refinement", "must be in 0..20");
}

double MeshVolume(const HullMesh& mesh) {
  double v = 0;
  for (const auto& t : mesh.triangles) {
    v += mesh.vertices[t[0]].dot(mesh.vertices[t[1]].cross(mesh.vertices[t[2]]));
  }
  return v / 6.0;
}

std::optional<HullMesh> PolyhedralVisualHull(const std::vector<Camera>& cameras,
                                             const std::vector<SilhouettePolygons>& polygons,
                                             const PolyhedralHullOptions& options) {
  options.Check();
  if (cameras.size() != polygons.size()) {
    throw InputError(
        "", "polygons",
        "expected one polygon set per camera (" + std::to_string(cameras.size()) + ")");
  }
  const size_t nc = cameras.size();
  std::vector<View> views(nc);
  for (size_t c = 0; c < nc; ++c) {
    const Camera& cam = cameras[c];
    View& v = views[c];
    v.camera = &cam;
    v.cam_from_world_rotation = cam.cam_from_world.linear();
    v.cam_from_world_translation = cam.cam_from_world.translation();
    for (const PolygonLoop& loop : polygons[c].loops) {
      std::vector<Eigen::Vector2d> n;
      for (const auto& px : loop.vertices) n.push_back(Normalised(cam, px));
      for (size_t i = 0; i < n.size(); ++i)
        v.edges.push_back(MakeEdge(n[i], n[(i + 1) % n.size()]));
      v.loops.push_back(std::move(n));
    }
    // The image border, as straight segments between undistorted corners
    // (an approximation under distortion: it only places interval ends).
    const double w = cam.width - 0.5, h = cam.height - 0.5;
    const Eigen::Vector2d corners[4] = {Normalised(cam, {-0.5, -0.5}), Normalised(cam, {w, -0.5}),
                                        Normalised(cam, {w, h}), Normalised(cam, {-0.5, h})};
    for (int i = 0; i < 4; ++i) v.border.push_back(MakeEdge(corners[i], corners[(i + 1) % 4]));
  }

  HullMesh mesh;
  std::vector<double> cuts;
  for (size_t m = 0; m < nc; ++m) {
    const Camera& cam = cameras[m];
    const Eigen::Vector3d centre = cam.CenterInWorld();
    // Intervals of the ray from C_m through pixel `px` inside every other
    // view's cone and the box.
    auto sample = [&](const Eigen::Vector2d& px) {
      RaySample r;
      const auto ray = cam.PixelRayInWorld(px);
      double s0 = 0, s1 = 0;
      if (!ray || !ClipToBox(centre, *ray, options.min_corner_m, options.max_corner_m, s0, s1))
        return r;
      r.dir = *ray;
      cuts.assign({s0, s1});
      for (size_t j = 0; j < nc; ++j) {
        if (j == m) continue;
        const View& v = views[j];
        const Eigen::Vector3d a = v.cam_from_world_rotation * centre + v.cam_from_world_translation;
        const Eigen::Vector3d b = v.cam_from_world_rotation * *ray;
        Crossings(v.edges, a, b, options.near_m, s0, s1, cuts);
        Crossings(v.border, a, b, options.near_m, s0, s1, cuts);
        if (std::abs(b.z()) > 1e-15) {
          const double s = (options.near_m - a.z()) / b.z();
          if (s > s0 && s < s1) cuts.push_back(s);
        }
      }
      std::sort(cuts.begin(), cuts.end());
      for (size_t i = 0; i + 1 < cuts.size(); ++i) {
        if (cuts[i + 1] - cuts[i] < 1e-9) continue;
        const Eigen::Vector3d mid = centre + 0.5 * (cuts[i] + cuts[i + 1]) * *ray;
        bool inside = true;
        for (size_t j = 0; j < nc && inside; ++j) {
          if (j != m) inside = Allows(views[j], mid, options.near_m);
        }
        if (!inside) continue;
        if (!r.intervals.empty() && std::abs(r.intervals.back().hi - cuts[i]) < 1e-9) {
          r.intervals.back().hi = cuts[i + 1];
        } else {
          r.intervals.push_back({cuts[i], cuts[i + 1]});
        }
      }
      r.ids.assign(2 * r.intervals.size(), -1);
      return r;
    };
    auto point = [&](const RaySample& r, size_t i, int end) {
      return Eigen::Vector3d(centre + (end ? r.intervals[i].hi : r.intervals[i].lo) * r.dir);
    };
    auto vertex = [&](RaySample& r, size_t i, int end) {
      int64_t& id = r.ids[2 * i + end];
      if (id < 0) {
        id = static_cast<int64_t>(mesh.vertices.size());
        mesh.vertices.push_back(point(r, i, end));
      }
      return static_cast<uint32_t>(id);
    };
    Eigen::Vector3d outward;
    // Joins overlapping intervals of two neighbouring rays by quads.
    auto join = [&](RaySample& a, RaySample& b) {
      size_t i = 0, j = 0;
      while (i < a.intervals.size() && j < b.intervals.size()) {
        if (std::min(a.intervals[i].hi, b.intervals[j].hi) >
            std::max(a.intervals[i].lo, b.intervals[j].lo)) {
          const uint32_t q[4] = {vertex(a, i, 0), vertex(a, i, 1), vertex(b, j, 1),
                                 vertex(b, j, 0)};
          const Eigen::Vector3d& p0 = mesh.vertices[q[0]];
          const Eigen::Vector3d n = (mesh.vertices[q[1]] - p0).cross(mesh.vertices[q[2]] - p0) +
                                    (mesh.vertices[q[2]] - p0).cross(mesh.vertices[q[3]] - p0);
          if (n.dot(outward) >= 0) {
            mesh.triangles.push_back({q[0], q[1], q[2]});
            mesh.triangles.push_back({q[0], q[2], q[3]});
          } else {
            mesh.triangles.push_back({q[0], q[2], q[1]});
            mesh.triangles.push_back({q[0], q[3], q[2]});
          }
          mesh.triangle_view.insert(mesh.triangle_view.end(), 2, static_cast<int>(m));
        }
        (a.intervals[i].hi < b.intervals[j].hi ? i : j)++;
      }
    };
    // Distance from p to the segment ab.
    auto off_chord = [](const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                        const Eigen::Vector3d& b) {
      const Eigen::Vector3d ab = b - a;
      const double t =
          ab.squaredNorm() > 0 ? std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0) : 0.0;
      return (a + t * ab - p).norm();
    };
    // Between rays at edge parameters t0 and t1: join them when the ray half
    // way has the same intervals and its ends lie on the chords (the patch is
    // a quad there); otherwise split, so interval births, deaths and kinks of
    // the patch outline are found to within 2^-max_refinement of a step.
    std::function<void(const Eigen::Vector2d&, const Eigen::Vector2d&, double, double, RaySample&,
                       RaySample&, int)>
        sweep = [&](const Eigen::Vector2d& pa, const Eigen::Vector2d& dir, double t0, double t1,
                    RaySample& a, RaySample& b, int depth) {
          if (a.intervals.empty() && b.intervals.empty() && depth > 0) return;
          const double tm = 0.5 * (t0 + t1);
          RaySample mid = sample(pa + tm * dir);
          bool same = a.intervals.size() == b.intervals.size() &&
                      mid.intervals.size() == a.intervals.size();
          for (size_t i = 0; same && i < a.intervals.size(); ++i) {
            same = off_chord(point(mid, i, 0), point(a, i, 0), point(b, i, 0)) <=
                       options.max_chord_error_m &&
                   off_chord(point(mid, i, 1), point(a, i, 1), point(b, i, 1)) <=
                       options.max_chord_error_m;
          }
          if (same || depth >= options.max_refinement) {
            join(a, b);
            return;
          }
          sweep(pa, dir, t0, tm, a, mid, depth + 1);
          sweep(pa, dir, tm, t1, mid, b, depth + 1);
        };

    for (const PolygonLoop& loop : polygons[m].loops) {
      const double area = SignedArea(loop.vertices);
      const double inward_sign = (area > 0 ? 1.0 : -1.0) * (loop.hole ? -1.0 : 1.0);
      const size_t nv = loop.vertices.size();
      for (size_t e = 0; e < nv; ++e) {
        const Eigen::Vector2d pa = loop.vertices[e], pb = loop.vertices[(e + 1) % nv];
        const Eigen::Vector2d dir = pb - pa;
        const double len = dir.norm();
        if (len < 1e-9) continue;
        const auto ra = cam.PixelRayInWorld(pa), rb = cam.PixelRayInWorld(pb);
        // The silhouette side of the edge: left of travel when the loop runs
        // with positive area, flipped for holes.
        const Eigen::Vector2d inward = inward_sign * Eigen::Vector2d(-dir.y(), dir.x()) / len;
        const auto rin = cam.PixelRayInWorld(0.5 * (pa + pb) + inward);
        if (!ra || !rb || !rin) continue;
        outward = ra->cross(*rb);
        if (outward.dot(*rin) > 0) outward = -outward;

        const int segments = std::clamp(static_cast<int>(std::ceil(len / options.ray_step_px)), 1,
                                        options.max_rays_per_edge);
        RaySample previous = sample(pa);
        for (int k = 1; k <= segments; ++k) {
          const double t0 = double(k - 1) / segments, t1 = double(k) / segments;
          RaySample current = sample(pa + t1 * dir);
          sweep(pa, dir, t0, t1, previous, current, 0);
          previous = std::move(current);
        }
      }
    }
  }
  // Drop the vertices of rays that no face uses.
  std::vector<int64_t> remap(mesh.vertices.size(), -1);
  std::vector<Eigen::Vector3d> used;
  for (auto& t : mesh.triangles) {
    for (uint32_t& i : t) {
      if (remap[i] < 0) {
        remap[i] = static_cast<int64_t>(used.size());
        used.push_back(mesh.vertices[i]);
      }
      i = static_cast<uint32_t>(remap[i]);
    }
  }
  mesh.vertices = std::move(used);
  if (mesh.triangles.empty()) return std::nullopt;
  return mesh;
}

}  // namespace irbench
