#include "tracker/nss/nss_skeleton.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>
#include <queue>

#include "common/atomic_file.h"
#include "common/error.h"

namespace irbench {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// The 26-neighbour graph of voxel cells, compressed rows.
struct Graph {
  std::vector<int> start;  // per voxel, its first edge; size n + 1
  std::vector<int> to;
  std::vector<double> length_m;
  int size() const { return static_cast<int>(start.size()) - 1; }
};

Graph BuildGraph(const std::vector<Eigen::Vector3i>& cells, double voxel_size_m) {
  Graph g;
  g.start.assign(1, 0);
  if (cells.empty()) return g;
  Eigen::Vector3i lo = cells[0], hi = cells[0];
  for (const Eigen::Vector3i& c : cells) lo = lo.cwiseMin(c), hi = hi.cwiseMax(c);
  const Eigen::Vector3i dims = hi - lo + Eigen::Vector3i::Ones();
  std::vector<int> lookup(size_t(dims.x()) * dims.y() * dims.z(), -1);
  const auto index = [&](const Eigen::Vector3i& c) { return (size_t(c.z()) * dims.y() + c.y()) * dims.x() + c.x(); };
  for (size_t i = 0; i < cells.size(); ++i) lookup[index(cells[i] - lo)] = static_cast<int>(i);
  for (const Eigen::Vector3i& cell : cells) {
    const Eigen::Vector3i c = cell - lo;
    for (int dz = -1; dz <= 1; ++dz) {
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          if (dx == 0 && dy == 0 && dz == 0) continue;
          const Eigen::Vector3i n = c + Eigen::Vector3i(dx, dy, dz);
          if ((n.array() < 0).any() || (n.array() >= dims.array()).any()) continue;
          const int j = lookup[index(n)];
          if (j < 0) continue;
          g.to.push_back(j);
          g.length_m.push_back(voxel_size_m * std::sqrt(double(dx * dx + dy * dy + dz * dz)));
        }
      }
    }
    g.start.push_back(static_cast<int>(g.to.size()));
  }
  return g;
}

std::vector<double> Dijkstra(const Graph& g, int from) {
  std::vector<double> d(g.size(), kInf);
  using Item = std::pair<double, int>;
  std::priority_queue<Item, std::vector<Item>, std::greater<>> queue;
  d[from] = 0;
  queue.push({0.0, from});
  while (!queue.empty()) {
    const auto [di, i] = queue.top();
    queue.pop();
    if (di > d[i]) continue;
    for (int e = g.start[i]; e < g.start[i + 1]; ++e) {
      const double dj = di + g.length_m[e];
      if (dj < d[g.to[e]]) {
        d[g.to[e]] = dj;
        queue.push({dj, g.to[e]});
      }
    }
  }
  return d;
}

// The cells of the largest connected part of the graph (ties: the first).
std::vector<Eigen::Vector3i> LargestPart(const std::vector<Eigen::Vector3i>& cells, const Graph& g) {
  std::vector<int> part(cells.size(), -1);
  std::vector<int> sizes;
  for (int s = 0; s < g.size(); ++s) {
    if (part[s] >= 0) continue;
    const int id = static_cast<int>(sizes.size());
    sizes.push_back(0);
    std::vector<int> stack{s};
    part[s] = id;
    while (!stack.empty()) {
      const int i = stack.back();
      stack.pop_back();
      ++sizes[id];
      for (int e = g.start[i]; e < g.start[i + 1]; ++e) {
        if (part[g.to[e]] < 0) {
          part[g.to[e]] = id;
          stack.push_back(g.to[e]);
        }
      }
    }
  }
  const int best = static_cast<int>(std::max_element(sizes.begin(), sizes.end()) - sizes.begin());
  std::vector<Eigen::Vector3i> out;
  for (size_t i = 0; i < cells.size(); ++i) {
    if (part[i] == best) out.push_back(cells[i]);
  }
  return out;
}

// Landmark Isomap: geodesics from `count` farthest-point landmarks, classical
// MDS of theirs to 3D, every voxel placed from its distances to them.
std::vector<Eigen::Vector3d> LandmarkIsomap(const Graph& g, int count) {
  const int n = g.size();
  std::vector<std::vector<double>> from;  // per landmark, distances to every voxel
  std::vector<int> landmarks;
  std::vector<double> nearest(n, kInf);
  const std::vector<double> d0 = Dijkstra(g, 0);
  int next = static_cast<int>(std::max_element(d0.begin(), d0.end()) - d0.begin());
  for (int k = 0; k < count; ++k) {
    landmarks.push_back(next);
    from.push_back(Dijkstra(g, next));
    for (int i = 0; i < n; ++i) nearest[i] = std::min(nearest[i], from.back()[i]);
    next = static_cast<int>(std::max_element(nearest.begin(), nearest.end()) - nearest.begin());
  }
  const int l = count;
  Eigen::MatrixXd sq(l, l);
  for (int a = 0; a < l; ++a) {
    for (int b = 0; b < l; ++b) sq(a, b) = from[a][landmarks[b]] * from[a][landmarks[b]];
  }
  sq = 0.5 * (sq + sq.transpose()).eval();
  const Eigen::VectorXd mean = sq.rowwise().mean();
  const Eigen::MatrixXd centring = Eigen::MatrixXd::Identity(l, l) - Eigen::MatrixXd::Constant(l, l, 1.0 / l);
  const Eigen::MatrixXd b = -0.5 * centring * sq * centring;
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(b);
  // The pseudo-inverse's rows for the three largest eigenvalues (de Silva
  // and Tenenbaum): y = -1/2 L# (delta - mean).
  Eigen::Matrix<double, 3, Eigen::Dynamic> pinv = Eigen::Matrix<double, 3, Eigen::Dynamic>::Zero(3, l);
  for (int k = 0; k < 3; ++k) {
    const double lambda = eigen.eigenvalues()(l - 1 - k);
    if (lambda > 1e-12) pinv.row(k) = eigen.eigenvectors().col(l - 1 - k).transpose() / std::sqrt(lambda);
  }
  std::vector<Eigen::Vector3d> y(n);
  Eigen::VectorXd delta(l);
  for (int i = 0; i < n; ++i) {
    for (int a = 0; a < l; ++a) delta(a) = from[a][i] * from[a][i] - mean(a);
    y[i] = -0.5 * pinv * delta;
  }
  return y;
}

int Find(std::vector<int>& parent, int i) {
  while (parent[i] != i) i = parent[i] = parent[parent[i]];
  return i;
}

// Sweep-and-prune: the voxels `members` (indices into y) whose boxes of
// half-size `half` overlap, chained, are one cluster; per member its
// cluster's representative.
std::vector<int> SweepAndPrune(const std::vector<Eigen::Vector3d>& y, const std::vector<int>& members, double half) {
  std::vector<int> order(members.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](int a, int b) {
    return y[members[a]].x() < y[members[b]].x() || (y[members[a]].x() == y[members[b]].x() && a < b);
  });
  std::vector<int> parent(members.size());
  std::iota(parent.begin(), parent.end(), 0);
  std::vector<int> active;
  for (const int a : order) {
    const Eigen::Vector3d& p = y[members[a]];
    active.erase(std::remove_if(active.begin(), active.end(), [&](int b) { return y[members[b]].x() + half < p.x() - half; }),
                 active.end());
    for (const int b : active) {
      const Eigen::Vector3d& q = y[members[b]];
      if (std::abs(p.y() - q.y()) <= 2 * half && std::abs(p.z() - q.z()) <= 2 * half) {
        parent[Find(parent, a)] = Find(parent, b);
      }
    }
    active.push_back(a);
  }
  std::vector<int> out(members.size());
  for (size_t a = 0; a < members.size(); ++a) out[a] = Find(parent, static_cast<int>(a));
  return out;
}

double PolylineLength(const std::vector<Eigen::Vector3d>& points) {
  double length = 0;
  for (size_t i = 1; i < points.size(); ++i) length += (points[i] - points[i - 1]).norm();
  return length;
}

// The point `distance` metres along a polyline (its end when shorter).
Eigen::Vector3d PointAlong(const std::vector<Eigen::Vector3d>& points, double distance) {
  for (size_t i = 1; i < points.size(); ++i) {
    const double step = (points[i] - points[i - 1]).norm();
    if (step >= distance && step > 0) return points[i - 1] + (points[i] - points[i - 1]) * (distance / step);
    distance -= step;
  }
  return points.back();
}

// The tree's segments between junctions (nodes with two or more significant
// children), the root and the leaves.
struct Tree {
  const std::vector<NssNode>& nodes;
  std::vector<std::vector<int>> children;
  std::vector<double> reach_m;  // how far the subtree goes beyond the node, in shells x width
  double min_branch_m;

  bool Significant(int child, double width) const { return reach_m[child] + width >= min_branch_m; }
  int SignificantChildren(int node, double width) const {
    int n = 0;
    for (int c : children[node]) n += Significant(c, width);
    return n;
  }
  // From `start` (a junction or the root) through `child`, along the
  // farthest-reaching child, to a leaf or the next junction.
  std::vector<int> Segment(int start, int child, double width, bool* ends_at_leaf) const {
    std::vector<int> path{start, child};
    int at = child;
    for (;;) {
      if (children[at].empty()) {
        *ends_at_leaf = true;
        return path;
      }
      if (SignificantChildren(at, width) >= 2) {
        *ends_at_leaf = false;
        return path;
      }
      at = *std::max_element(children[at].begin(), children[at].end(),
                             [&](int a, int b) { return reach_m[a] < reach_m[b]; });
      path.push_back(at);
    }
  }
};

// 6. The tree's segments from the root outwards; those that end at a leaf
// are limbs, labelled; then the torso.
std::vector<NssCurve> LabelledCurves(const std::vector<NssNode>& nodes, const Tree& tree, int root,
                                     const Eigen::Vector2d& facing_xy, const NssOptions& options) {
  std::vector<NssCurve> curves;
  const double w = options.shell_width_m;
  struct Segment {
    std::vector<int> nodes;
    bool limb = false;
  };
  std::vector<Segment> segments;
  std::vector<int> starts{root};
  while (!starts.empty()) {
    const int start = starts.back();
    starts.pop_back();
    for (int c : tree.children[start]) {
      if (!tree.Significant(c, w)) continue;
      Segment s;
      s.nodes = tree.Segment(start, c, w, &s.limb);
      if (!s.limb) starts.push_back(s.nodes.back());
      segments.push_back(std::move(s));
    }
  }
  const auto points_of = [&](const std::vector<int>& path) {
    std::vector<Eigen::Vector3d> points;
    for (int n : path) points.push_back(nodes[n].p_in_world);
    return points;
  };
  // Upper and lower: which side of the root (in world z) a segment's
  // junction lies; left and right from the facing.
  const Eigen::Vector3d root_p = nodes[root].p_in_world;
  Eigen::Vector2d front = facing_xy.norm() > 0 ? facing_xy.normalized() : Eigen::Vector2d(0, 1);
  const Eigen::Vector2d right(front.y(), -front.x());
  const auto lateral = [&](const std::vector<Eigen::Vector3d>& points) {
    const Eigen::Vector3d p = PointAlong(points, 0.15);
    return right.dot((p - root_p).head<2>());
  };
  std::vector<NssCurve> upper, lower;
  for (const Segment& s : segments) {
    if (!s.limb) continue;
    NssCurve curve;
    curve.nodes = s.nodes;
    curve.points_in_world = points_of(s.nodes);
    curve.length_m = PolylineLength(curve.points_in_world);
    if (curve.length_m < options.min_branch_m) continue;
    curve.label = "limb";
    (nodes[s.nodes.front()].p_in_world.z() >= root_p.z() ? upper : lower).push_back(std::move(curve));
  }
  if (upper.size() == 3) {
    const auto head = std::min_element(upper.begin(), upper.end(),
                                       [](const NssCurve& a, const NssCurve& b) { return a.length_m < b.length_m; });
    head->label = "head";
  }
  const auto sides = [&](std::vector<NssCurve>& limbs, const std::string& kind) {
    std::vector<NssCurve*> two;
    for (NssCurve& c : limbs) {
      if (c.label == "limb") two.push_back(&c);
    }
    if (two.size() != 2) return;
    const bool first_right = lateral(two[0]->points_in_world) > lateral(two[1]->points_in_world);
    two[first_right ? 0 : 1]->label = "right_" + kind;
    two[first_right ? 1 : 0]->label = "left_" + kind;
  };
  sides(upper, "arm");
  sides(lower, "leg");
  for (NssCurve& c : upper) curves.push_back(std::move(c));
  for (NssCurve& c : lower) curves.push_back(std::move(c));
  // The torso: the tree's path from its lowest junction to its highest
  // (junctions: where segments end that are not limbs; and the root).
  int low = root, high = root;
  for (const Segment& s : segments) {
    if (s.limb) continue;
    const int j = s.nodes.back();
    if (nodes[j].p_in_world.z() < nodes[low].p_in_world.z()) low = j;
    if (nodes[j].p_in_world.z() > nodes[high].p_in_world.z()) high = j;
  }
  const auto up_to_root = [&](int n) {
    std::vector<int> path{n};
    while (nodes[path.back()].parent >= 0) path.push_back(nodes[path.back()].parent);
    return path;
  };
  std::vector<int> from_low = up_to_root(low), from_high = up_to_root(high);
  while (from_low.size() > 1 && from_high.size() > 1 && from_low[from_low.size() - 2] == from_high[from_high.size() - 2]) {
    from_low.pop_back();  // below their lowest common ancestor, both paths are the same
    from_high.pop_back();
  }
  NssCurve torso;
  torso.label = "torso";
  torso.nodes = from_low;  // low ... common ancestor
  torso.nodes.insert(torso.nodes.end(), from_high.rbegin() + 1, from_high.rend());
  torso.points_in_world = points_of(torso.nodes);
  torso.length_m = PolylineLength(torso.points_in_world);
  curves.push_back(std::move(torso));
  return curves;
}

}  // namespace

void NssOptions::Check() const {
  if (landmarks < 4) throw InputError("", "nss.landmarks", "must be at least 4");
  if (!(shell_width_m > 0)) throw InputError("", "nss.shell_width_m", "must be > 0");
  if (!(prune_box_voxels > 0)) throw InputError("", "nss.prune_box_voxels", "must be > 0");
  if (min_cluster_voxels < 1) throw InputError("", "nss.min_cluster_voxels", "must be at least 1");
  if (!(min_branch_m >= 0)) throw InputError("", "nss.min_branch_m", "must be >= 0");
}

const NssCurve* NssSkeleton::Find(const std::string& label) const {
  for (const NssCurve& c : curves) {
    if (c.label == label) return &c;
  }
  return nullptr;
}

std::vector<double> VoxelGeodesics(const std::vector<Eigen::Vector3i>& cells, double voxel_size_m, int from) {
  return Dijkstra(BuildGraph(cells, voxel_size_m), from);
}

NssSkeleton ComputeNssSkeleton(const VoxelHull& hull, const Eigen::Vector2d& facing_xy, const NssOptions& options) {
  options.Check();
  NssSkeleton out;
  const double voxel = hull.voxel_size_m;
  // 1. The occupied voxels' largest connected part and its Isomap.
  std::array<int, 6> box{0, 0, 0, hull.nx, hull.ny, hull.nz};
  if (hull.occupied_within) box = *hull.occupied_within;
  std::vector<Eigen::Vector3i> cells;
  for (int z = box[2]; z < box[5]; ++z) {
    for (int y = box[1]; y < box[4]; ++y) {
      for (int x = box[0]; x < box[3]; ++x) {
        if (hull.Occupied(x, y, z)) cells.emplace_back(x, y, z);
      }
    }
  }
  if (cells.empty()) return out;
  cells = LargestPart(cells, BuildGraph(cells, voxel));
  out.voxels = static_cast<int>(cells.size());
  if (out.voxels < options.landmarks) return out;
  const Graph graph = BuildGraph(cells, voxel);
  const std::vector<Eigen::Vector3d> y = LandmarkIsomap(graph, options.landmarks);
  std::vector<Eigen::Vector3d> centres;
  for (const Eigen::Vector3i& c : cells) centres.push_back(hull.VoxelCenter(c.x(), c.y(), c.z()));

  // 2. Shells about the embedding's mean.
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : y) mean += p;
  mean /= static_cast<double>(y.size());
  std::vector<int> shell(y.size());
  int shells = 0;
  for (size_t i = 0; i < y.size(); ++i) {
    shell[i] = static_cast<int>((y[i] - mean).norm() / options.shell_width_m);
    shells = std::max(shells, shell[i] + 1);
  }
  std::vector<std::vector<int>> in_shell(shells);
  for (size_t i = 0; i < y.size(); ++i) in_shell[shell[i]].push_back(static_cast<int>(i));

  // 3. Clusters per shell by sweep-and-prune; 5. their Shepard points.
  std::vector<int> node_of(y.size(), -1);
  for (int s = 0; s < shells; ++s) {
    const std::vector<int>& members = in_shell[s];
    const std::vector<int> group = SweepAndPrune(y, members, options.prune_box_voxels * voxel);
    std::map<int, std::vector<int>> clusters;
    for (size_t a = 0; a < members.size(); ++a) clusters[group[a]].push_back(members[a]);
    for (const auto& [rep, voxels] : clusters) {
      if (static_cast<int>(voxels.size()) < options.min_cluster_voxels) continue;
      NssNode node;
      node.shell = s;
      node.voxels = static_cast<int>(voxels.size());
      for (int i : voxels) node.p_in_embedding += y[i];
      node.p_in_embedding /= static_cast<double>(voxels.size());
      double weights = 0;
      for (int i : voxels) {
        const double w = 1.0 / ((y[i] - node.p_in_embedding).squaredNorm() + 0.25 * voxel * voxel);
        node.p_in_world += w * centres[i];
        weights += w;
        node_of[i] = static_cast<int>(out.nodes.size());
      }
      node.p_in_world /= weights;
      out.nodes.push_back(node);
    }
  }
  out.voxel_centres = centres;
  out.embedded = y;
  if (out.nodes.empty()) return out;

  // 4. The tree: each node's parent is the node one shell in that its
  // voxels share the most graph edges with.
  std::vector<std::map<int, int>> links(out.nodes.size());
  for (int i = 0; i < graph.size(); ++i) {
    if (node_of[i] < 0) continue;
    for (int e = graph.start[i]; e < graph.start[i + 1]; ++e) {
      const int j = graph.to[e];
      if (node_of[j] >= 0 && shell[j] == shell[i] - 1) ++links[node_of[i]][node_of[j]];
    }
  }
  for (size_t n = 0; n < out.nodes.size(); ++n) {
    int best = -1, most = 0;
    for (const auto& [m, count] : links[n]) {
      if (count > most) best = m, most = count;
    }
    out.nodes[n].parent = best;
  }
  // The root: the innermost shell's largest node; nodes that do not reach it
  // stay out of the curves.
  int root = 0;
  for (size_t n = 0; n < out.nodes.size(); ++n) {
    const NssNode& a = out.nodes[n];
    const NssNode& r = out.nodes[root];
    if (a.shell < r.shell || (a.shell == r.shell && a.voxels > r.voxels)) root = static_cast<int>(n);
  }
  out.nodes[root].parent = -1;
  Tree tree{out.nodes, std::vector<std::vector<int>>(out.nodes.size()), std::vector<double>(out.nodes.size(), 0.0),
            options.min_branch_m};
  for (size_t n = 0; n < out.nodes.size(); ++n) {
    if (out.nodes[n].parent >= 0) tree.children[out.nodes[n].parent].push_back(static_cast<int>(n));
  }
  // Reach: nodes in order of decreasing shell, so children come first.
  std::vector<int> by_shell(out.nodes.size());
  std::iota(by_shell.begin(), by_shell.end(), 0);
  std::sort(by_shell.begin(), by_shell.end(), [&](int a, int b) { return out.nodes[a].shell > out.nodes[b].shell; });
  for (int n : by_shell) {
    for (int c : tree.children[n]) tree.reach_m[n] = std::max(tree.reach_m[n], tree.reach_m[c] + options.shell_width_m);
  }

  out.curves = LabelledCurves(out.nodes, tree, root, facing_xy, options);
  return out;
}

void WriteNssPly(const std::filesystem::path& path, const NssSkeleton& skeleton) {
  const std::map<std::string, std::array<int, 3>> colours = {
      {"head", {255, 255, 255}},   {"torso", {160, 160, 160}}, {"right_arm", {230, 60, 40}},
      {"left_arm", {40, 120, 230}}, {"right_leg", {240, 170, 40}}, {"left_leg", {60, 190, 90}}};
  std::string vertices, edges;
  int count = 0, edge_count = 0;
  char buffer[96];
  for (const NssCurve& c : skeleton.curves) {
    const auto it = colours.find(c.label);
    const std::array<int, 3> rgb = it == colours.end() ? std::array<int, 3>{200, 0, 200} : it->second;
    for (size_t i = 0; i < c.points_in_world.size(); ++i) {
      const Eigen::Vector3d& p = c.points_in_world[i];
      std::snprintf(buffer, sizeof(buffer), "%.4f %.4f %.4f %d %d %d\n", p.x(), p.y(), p.z(), rgb[0], rgb[1], rgb[2]);
      vertices += buffer;
      if (i > 0) {
        edges += std::to_string(count - 1) + " " + std::to_string(count) + "\n";
        ++edge_count;
      }
      ++count;
    }
  }
  AtomicWriteFile(path, "ply\nformat ascii 1.0\ncomment irbench NSS skeleton (thesis 4.4.1), world metres, z up\n"
                        "element vertex " + std::to_string(count) +
                            "\nproperty float x\nproperty float y\nproperty float z\n"
                            "property uchar red\nproperty uchar green\nproperty uchar blue\n"
                            "element edge " + std::to_string(edge_count) +
                            "\nproperty int vertex1\nproperty int vertex2\nend_header\n" + vertices + edges);
}

}  // namespace irbench
