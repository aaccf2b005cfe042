#include "tracker/hull/polyhedral_hull.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
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
  const Eigen::Vector2d xd = cam.PixelToNormalised(px);
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

// Distance from p to the segment ab.
double OffChord(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  const Eigen::Vector3d ab = b - a;
  const double t =
      ab.squaredNorm() > 0 ? std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0) : 0.0;
  return (a + t * ab - p).norm();
}

// The views as the other views' rays see them: each camera's polygon edges and
// image border in its undistorted normalised image plane.
std::vector<View> MakeViews(const std::vector<Camera>& cameras,
                            const std::vector<SilhouettePolygons>& polygons) {
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
  return views;
}

// Sweeps the wedges of view m's polygon edges through the other views' cones
// and appends the patches to `mesh` (their faces tagged with view m).
class WedgeSweep {
 public:
  // `cuts`: scratch for the ray parameters, shared between sweeps.
  WedgeSweep(const std::vector<View>& views,
             size_t m,
             const PolyhedralHullOptions& options,
             std::vector<double>& cuts,
             HullMesh& mesh)
      : views_(views),
        m_(m),
        cam_(*views[m].camera),
        centre_(cam_.CenterInWorld()),
        options_(options),
        cuts_(cuts),
        mesh_(mesh) {}

  // Sweeps the wedges of every edge of `loop` (a loop of view m's polygons).
  void SweepLoop(const PolygonLoop& loop);

 private:
  // Intervals of the ray from C_m through pixel `px` inside every other
  // view's cone and the box.
  RaySample Sample(const Eigen::Vector2d& px);
  // End `end` (0: lo, 1: hi) of interval i of ray r, world metres.
  Eigen::Vector3d Point(const RaySample& r, size_t i, int end) const {
    return Eigen::Vector3d(centre_ + (end ? r.intervals[i].hi : r.intervals[i].lo) * r.dir);
  }
  // The mesh vertex at that end, made on first use.
  uint32_t Vertex(RaySample& r, size_t i, int end);
  // Joins overlapping intervals of two neighbouring rays by quads.
  void Join(RaySample& a, RaySample& b);
  // Between rays at edge parameters t0 and t1: join them when the ray half
  // way has the same intervals and its ends lie on the chords (the patch is
  // a quad there); otherwise split, so interval births, deaths and kinks of
  // the patch outline are found to within 2^-max_refinement of a step.
  void Sweep(const Eigen::Vector2d& pa,
             const Eigen::Vector2d& dir,
             double t0,
             double t1,
             RaySample& a,
             RaySample& b,
             int depth);

  const std::vector<View>& views_;
  const size_t m_;
  const Camera& cam_;
  const Eigen::Vector3d centre_;
  const PolyhedralHullOptions& options_;
  std::vector<double>& cuts_;
  HullMesh& mesh_;
  Eigen::Vector3d outward_;  // away from the silhouette side of the current edge's wedge
};

RaySample WedgeSweep::Sample(const Eigen::Vector2d& px) {
  const size_t nc = views_.size();
  RaySample r;
  const auto ray = cam_.PixelRayInWorld(px);
  double s0 = 0, s1 = 0;
  if (!ray || !ClipToBox(centre_, *ray, options_.min_corner_m, options_.max_corner_m, s0, s1))
    return r;
  r.dir = *ray;
  cuts_.assign({s0, s1});
  for (size_t j = 0; j < nc; ++j) {
    if (j == m_) continue;
    const View& v = views_[j];
    const Eigen::Vector3d a = v.cam_from_world_rotation * centre_ + v.cam_from_world_translation;
    const Eigen::Vector3d b = v.cam_from_world_rotation * *ray;
    Crossings(v.edges, a, b, options_.near_m, s0, s1, cuts_);
    Crossings(v.border, a, b, options_.near_m, s0, s1, cuts_);
    if (std::abs(b.z()) > 1e-15) {
      const double s = (options_.near_m - a.z()) / b.z();
      if (s > s0 && s < s1) cuts_.push_back(s);
    }
  }
  std::sort(cuts_.begin(), cuts_.end());
  for (size_t i = 0; i + 1 < cuts_.size(); ++i) {
    if (cuts_[i + 1] - cuts_[i] < 1e-9) continue;
    const Eigen::Vector3d mid = centre_ + 0.5 * (cuts_[i] + cuts_[i + 1]) * *ray;
    bool inside = true;
    for (size_t j = 0; j < nc && inside; ++j) {
      if (j != m_) inside = Allows(views_[j], mid, options_.near_m);
    }
    if (!inside) continue;
    if (!r.intervals.empty() && std::abs(r.intervals.back().hi - cuts_[i]) < 1e-9) {
      r.intervals.back().hi = cuts_[i + 1];
    } else {
      r.intervals.push_back({cuts_[i], cuts_[i + 1]});
    }
  }
  r.ids.assign(2 * r.intervals.size(), -1);
  return r;
}

uint32_t WedgeSweep::Vertex(RaySample& r, size_t i, int end) {
  int64_t& id = r.ids[2 * i + end];
  if (id < 0) {
    id = static_cast<int64_t>(mesh_.vertices.size());
    mesh_.vertices.push_back(Point(r, i, end));
  }
  return static_cast<uint32_t>(id);
}

void WedgeSweep::Join(RaySample& a, RaySample& b) {
  size_t i = 0, j = 0;
  while (i < a.intervals.size() && j < b.intervals.size()) {
    if (std::min(a.intervals[i].hi, b.intervals[j].hi) >
        std::max(a.intervals[i].lo, b.intervals[j].lo)) {
      const uint32_t q[4] = {Vertex(a, i, 0), Vertex(a, i, 1), Vertex(b, j, 1),
                             Vertex(b, j, 0)};
      const Eigen::Vector3d& p0 = mesh_.vertices[q[0]];
      const Eigen::Vector3d n = (mesh_.vertices[q[1]] - p0).cross(mesh_.vertices[q[2]] - p0) +
                                (mesh_.vertices[q[2]] - p0).cross(mesh_.vertices[q[3]] - p0);
      if (n.dot(outward_) >= 0) {
        mesh_.triangles.push_back({q[0], q[1], q[2]});
        mesh_.triangles.push_back({q[0], q[2], q[3]});
      } else {
        mesh_.triangles.push_back({q[0], q[2], q[1]});
        mesh_.triangles.push_back({q[0], q[3], q[2]});
      }
      mesh_.triangle_view.insert(mesh_.triangle_view.end(), 2, static_cast<int>(m_));
    }
    (a.intervals[i].hi < b.intervals[j].hi ? i : j)++;
  }
}

void WedgeSweep::Sweep(const Eigen::Vector2d& pa,
                       const Eigen::Vector2d& dir,
                       double t0,
                       double t1,
                       RaySample& a,
                       RaySample& b,
                       int depth) {
  if (a.intervals.empty() && b.intervals.empty() && depth > 0) return;
  const double tm = 0.5 * (t0 + t1);
  RaySample mid = Sample(pa + tm * dir);
  bool same = a.intervals.size() == b.intervals.size() &&
              mid.intervals.size() == a.intervals.size();
  for (size_t i = 0; same && i < a.intervals.size(); ++i) {
    same = OffChord(Point(mid, i, 0), Point(a, i, 0), Point(b, i, 0)) <=
               options_.max_chord_error_m &&
           OffChord(Point(mid, i, 1), Point(a, i, 1), Point(b, i, 1)) <=
               options_.max_chord_error_m;
  }
  if (same || depth >= options_.max_refinement) {
    Join(a, b);
    return;
  }
  Sweep(pa, dir, t0, tm, a, mid, depth + 1);
  Sweep(pa, dir, tm, t1, mid, b, depth + 1);
}

void WedgeSweep::SweepLoop(const PolygonLoop& loop) {
  const double area = SignedArea(loop.vertices);
  const double inward_sign = (area > 0 ? 1.0 : -1.0) * (loop.hole ? -1.0 : 1.0);
  const size_t nv = loop.vertices.size();
  for (size_t e = 0; e < nv; ++e) {
    const Eigen::Vector2d pa = loop.vertices[e], pb = loop.vertices[(e + 1) % nv];
    const Eigen::Vector2d dir = pb - pa;
    const double len = dir.norm();
    if (len < 1e-9) continue;
    const auto ra = cam_.PixelRayInWorld(pa), rb = cam_.PixelRayInWorld(pb);
    // The silhouette side of the edge: left of travel when the loop runs
    // with positive area, flipped for holes.
    const Eigen::Vector2d inward = inward_sign * Eigen::Vector2d(-dir.y(), dir.x()) / len;
    const auto rin = cam_.PixelRayInWorld(0.5 * (pa + pb) + inward);
    if (!ra || !rb || !rin) continue;
    outward_ = ra->cross(*rb);
    if (outward_.dot(*rin) > 0) outward_ = -outward_;

    const int segments = std::clamp(static_cast<int>(std::ceil(len / options_.ray_step_px)), 1,
                                    options_.max_rays_per_edge);
    RaySample previous = Sample(pa);
    for (int k = 1; k <= segments; ++k) {
      const double t0 = double(k - 1) / segments, t1 = double(k) / segments;
      RaySample current = Sample(pa + t1 * dir);
      Sweep(pa, dir, t0, t1, previous, current, 0);
      previous = std::move(current);
    }
  }
}

// Drops the vertices of rays that no face uses (the rest keep their order of
// first use by the faces).
void DropUnusedVertices(HullMesh& mesh) {
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
}

}  // namespace

void PolyhedralHullOptions::Check() const {
  for (int a = 0; a < 3; ++a) {
    if (!(max_corner_m[a] > min_corner_m[a]))
      throw InputError("", "polyhedral.max_corner_m", "must exceed min_corner_m on every axis");
  }
  if (!(ray_step_px > 0)) throw InputError("", "polyhedral.ray_step_px", "must be > 0");
  if (max_rays_per_edge < 1) throw InputError("", "polyhedral.max_rays_per_edge", "must be >= 1");
  if (!(near_m > 0)) throw InputError("", "polyhedral.near_m", "must be > 0");
  if (!(max_chord_error_m > 0)) throw InputError("", "polyhedral.max_chord_error_m", "must be > 0");
  if (max_refinement < 0 || max_refinement > 20)
    throw InputError("", "polyhedral.max_refinement", "must be in 0..20");
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
  const std::vector<View> views = MakeViews(cameras, polygons);

  HullMesh mesh;
  std::vector<double> cuts;
  for (size_t m = 0; m < nc; ++m) {
    WedgeSweep sweep(views, m, options, cuts, mesh);
    for (const PolygonLoop& loop : polygons[m].loops) sweep.SweepLoop(loop);
  }
  DropUnusedVertices(mesh);
  if (mesh.triangles.empty()) return std::nullopt;
  return mesh;
}

}  // namespace irbench
