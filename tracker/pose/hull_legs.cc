#include "tracker/pose/hull_legs.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>
#include <vector>

#include "common/error.h"
#include "tracker/pose/internal/hull_column.h"

namespace irbench {

void HullLegsOptions::Check() const {
  const std::string where = "hull_legs";
  if (!(low > 0 && high > low && high < 0.5)) throw InputError("", where + ".high", "need 0 < low < high < 0.5");
  if (!(layer_m > 0 && layer_m < 0.2)) throw InputError("", where + ".layer_m", "must be in (0, 0.2)");
  if (min_layers < 2) throw InputError("", where + ".min_layers", "must be at least 2");
  if (min_layer_voxels < 1) throw InputError("", where + ".min_layer_voxels", "must be at least 1");
  if (!(ankle >= 0 && ankle < low)) throw InputError("", where + ".ankle", "must be in [0, low)");
  if (!(std::abs(calf) < 0.05)) throw InputError("", where + ".calf", "must be within +-0.05");
  if (!(radius_m > 0)) throw InputError("", where + ".radius_m", "must be > 0");
  if (!(max_slope > 0)) throw InputError("", where + ".max_slope", "must be > 0");
  if (!(root_max_slope >= max_slope)) throw InputError("", where + ".root_max_slope", "must be >= max_slope");
  if (!(max_lean >= 0 && max_lean <= max_slope)) throw InputError("", where + ".max_lean", "must be in [0, max_slope]");
  if (!(anchor_high > low && anchor_high <= high)) throw InputError("", where + ".anchor_high", "must be in (low, high]");
  if (!(weight >= 0 && weight <= 1)) throw InputError("", where + ".weight", "must be in [0, 1]");
  if (!(max_offset_m > 0)) throw InputError("", where + ".max_offset_m", "must be > 0");
  if (!(feet > 0 && feet <= ankle + 0.02)) throw InputError("", where + ".feet", "must be in (0, ankle + 0.02]");
  if (min_feet_voxels < 1) throw InputError("", where + ".min_feet_voxels", "must be at least 1");
}

namespace {

// The centre of a layer's voxels (x, y): their centroid, or with `split` the
// midpoint of the two groups that best split them along their principal
// axis (1-D 2-means, solved exactly: the split of the sorted projections
// with the least within-group squares). Two legs apart are then weighted
// alike whatever voxels each holds (one seen by fewer views, a ghost
// beside one), as the truth's midpoint of the ankles is; one blob's two
// halves straddle its centre.
Eigen::Vector2d LayerCentre(const std::vector<Eigen::Vector2d>& points, bool split) {
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (const Eigen::Vector2d& p : points) mean += p;
  mean /= static_cast<double>(points.size());
  if (!split || points.size() < 2) return mean;
  Eigen::Matrix2d cov = Eigen::Matrix2d::Zero();
  for (const Eigen::Vector2d& p : points) cov += (p - mean) * (p - mean).transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eigen(cov);
  const Eigen::Vector2d axis = eigen.eigenvectors().col(1);  // the largest eigenvalue's
  std::vector<std::pair<double, int>> along(points.size());
  for (size_t i = 0; i < points.size(); ++i) along[i] = {(points[i] - mean).dot(axis), static_cast<int>(i)};
  std::sort(along.begin(), along.end());
  const int n = static_cast<int>(along.size());
  std::vector<double> sum(n + 1, 0.0), sum2(n + 1, 0.0);
  for (int i = 0; i < n; ++i) {
    sum[i + 1] = sum[i] + along[i].first;
    sum2[i + 1] = sum2[i] + along[i].first * along[i].first;
  }
  int best = 1;
  double best_ss = std::numeric_limits<double>::infinity();
  for (int k = 1; k < n; ++k) {  // the first k against the rest
    const double low = sum2[k] - sum[k] * sum[k] / k;
    const double high = (sum2[n] - sum2[k]) - (sum[n] - sum[k]) * (sum[n] - sum[k]) / (n - k);
    if (low + high < best_ss) best_ss = low + high, best = k;
  }
  Eigen::Vector2d first = Eigen::Vector2d::Zero(), second = Eigen::Vector2d::Zero();
  for (int i = 0; i < n; ++i) (i < best ? first : second) += points[along[i].second];
  return (first / best + second / (n - best)) / 2;
}

// The ankles' midpoint from the layers' centres (LayerCentre): the lean, a
// least-squares line of the centres against their heights, capped at
// max_lean; the lowest layers' (below anchor_high) centre carried down the
// lean to the ankles' height `ankle_z` (a kink at the knee or a calf seen
// by fewer views bends the upper layers: the lean from them is trusted only
// so far). nullopt with fewer than min_layers layers or a lean beyond
// root_max_slope. `layers`: the layers fitted; `slope`: the line's lean
// (before the cap).
std::optional<Eigen::Vector2d> AnklesFromLayers(const std::vector<std::vector<Eigen::Vector2d>>& layer_points,
                                                bool split, double low, double ankle_z, double height_m,
                                                const HullLegsOptions& options, int* layers, double* slope) {
  Eigen::Matrix2d ata = Eigen::Matrix2d::Zero();
  Eigen::Matrix2d atb = Eigen::Matrix2d::Zero();  // columns x, y
  Eigen::Vector2d anchor = Eigen::Vector2d::Zero();
  double anchor_z = 0;
  int anchor_layers = 0;
  *layers = 0;
  for (size_t i = 0; i < layer_points.size(); ++i) {
    if (static_cast<int>(layer_points[i].size()) < options.min_layer_voxels) continue;
    const Eigen::Vector2d centre = LayerCentre(layer_points[i], split);
    const double z = low + (static_cast<double>(i) + 0.5) * options.layer_m;
    const Eigen::Vector2d a(1.0, z - ankle_z);
    ata += a * a.transpose();
    atb += a * centre.transpose();
    ++*layers;
    if (z < options.anchor_high * height_m) {
      anchor += centre;
      anchor_z += z;
      ++anchor_layers;
    }
  }
  if (*layers < options.min_layers || anchor_layers == 0 || std::abs(ata.determinant()) < 1e-12) return std::nullopt;
  const Eigen::Matrix2d line = ata.ldlt().solve(atb);  // row 0: intercept (x, y); row 1: slope
  Eigen::Vector2d lean = line.row(1).transpose();
  *slope = lean.norm();
  if (*slope > options.root_max_slope) return std::nullopt;
  if (*slope > options.max_lean) lean *= options.max_lean / *slope;
  return Eigen::Vector2d(anchor / anchor_layers - lean * (anchor_z / anchor_layers - ankle_z));
}

}  // namespace

std::optional<HullLegs> MeasureHullLegs(const VoxelHull& hull, const Eigen::Vector3d& model_root,
                                        const Eigen::Vector3d& forward, double height_m,
                                        const HullLegsOptions& options) {
  if (!(height_m > 0)) return std::nullopt;
  const double low = options.low * height_m, high = options.high * height_m;
  const int layer_count = std::max(1, static_cast<int>(std::floor((high - low) / options.layer_m)));
  std::vector<std::vector<Eigen::Vector2d>> layer_points(layer_count);
  std::vector<Eigen::Vector2d> feet_points;
  const double r2 = options.radius_m * options.radius_m;
  for (const Eigen::Vector3d& c : hull.OccupiedCenters()) {
    if (c.z() >= low + layer_count * options.layer_m) continue;
    if ((c.head<2>() - model_root.head<2>()).squaredNorm() > r2) continue;
    if (c.z() < options.feet * height_m) feet_points.push_back(c.head<2>());
    if (c.z() < low) continue;
    const int layer = static_cast<int>((c.z() - low) / options.layer_m);
    if (layer < 0 || layer >= layer_count) continue;
    layer_points[layer].push_back(c.head<2>());
  }
  // The ankles from the voxels' centroids: the feet's direction is read
  // from these (below). The root from the layers' two-leg midpoints
  // (split_legs) where they give one.
  const double ankle_z = options.ankle * height_m;
  int layers = 0;
  double slope = 0;
  const std::optional<Eigen::Vector2d> ankles =
      AnklesFromLayers(layer_points, false, low, ankle_z, height_m, options, &layers, &slope);
  if (!ankles) return std::nullopt;
  Eigen::Vector2d facing = forward.head<2>();
  facing = facing.norm() > 1e-9 ? facing.normalized() : Eigen::Vector2d::Zero();
  const auto near_model = [&](const Eigen::Vector2d& ankles_xy) -> std::optional<Eigen::Vector2d> {
    const Eigen::Vector2d measured = ankles_xy + options.calf * height_m * facing;
    if ((measured - model_root.head<2>()).norm() > options.max_offset_m) return std::nullopt;
    return measured;
  };
  std::optional<Eigen::Vector2d> measured = near_model(*ankles);
  if (!measured) return std::nullopt;
  if (options.split_legs) {
    int split_layers = 0;
    double split_slope = 0;
    const auto split =
        AnklesFromLayers(layer_points, true, low, ankle_z, height_m, options, &split_layers, &split_slope);
    if (const auto from_split = split ? near_model(*split) : std::nullopt) measured = from_split;
  }
  const Eigen::Vector2d root = model_root.head<2>() + options.weight * (*measured - model_root.head<2>());
  HullLegs out;
  out.root = Eigen::Vector3d(root.x(), root.y(), 0.0);
  out.layers = layers;
  if (slope <= options.max_slope && static_cast<int>(feet_points.size()) >= options.min_feet_voxels) {
    out.toes = LayerCentre(feet_points, false) - *ankles;
  }
  return out;
}

Eigen::Vector3d RootOffsetMemory::Root(const Eigen::Vector3d& model_root, const Eigen::Vector3d& forward,
                                       const std::optional<HullLegs>& legs, double dt) {
  if (!legs) gap_s_ += dt;
  // A body with no direction on the floor can neither keep nor apply an
  // offset in its frame.
  const Eigen::Vector2d flat = forward.head<2>();
  if (flat.norm() <= 1e-9) return legs ? legs->root : model_root;
  const Eigen::Vector2d ahead = flat.normalized();
  const Eigen::Vector2d left(-ahead.y(), ahead.x());
  // The average as it stands: faded over the time without a measure.
  const Eigen::Vector2d faded = std::exp(-gap_s_ / memory_s_) * offset_;
  if (!legs) {
    Eigen::Vector3d root = model_root;
    root.head<2>() += faded.x() * ahead + faded.y() * left;
    return root;
  }
  const Eigen::Vector2d d = legs->root.head<2>() - model_root.head<2>();
  const double keep = measured_ ? std::exp(-dt / smoothing_s_) : 0.0;
  offset_ = keep * faded + (1 - keep) * Eigen::Vector2d(d.dot(ahead), d.dot(left));
  measured_ = true;
  gap_s_ = 0;
  return legs->root;
}

namespace {

// Visits the occupied voxels within radius_m of `root` (horizontally), layer
// by layer from the floor up, while their layer's centre lies below top_m;
// stops when `visit` (given the voxel's centre) returns true.
template <typename Visit>
void VisitLowVoxels(const VoxelHull& hull, const Eigen::Vector3d& root, double radius_m, double top_m, Visit visit) {
  const double r2 = radius_m * radius_m;
  for (int z = 0; z < hull.nz; ++z) {
    if (hull.VoxelCenter(0, 0, z).z() >= top_m) return;
    for (int y = 0; y < hull.ny; ++y) {
      for (int x = 0; x < hull.nx; ++x) {
        if (!hull.Occupied(x, y, z)) continue;
        const Eigen::Vector3d c = hull.VoxelCenter(x, y, z);
        if ((c.head<2>() - root.head<2>()).squaredNorm() > r2) continue;
        if (visit(c)) return;
      }
    }
  }
}

}  // namespace

bool FeetOnFloor(const VoxelHull& hull, const Eigen::Vector3d& root, double height_m,
                 const HullLegsOptions& options) {
  if (hull.voxel_size_m <= 0) return false;
  int count = 0;
  VisitLowVoxels(hull, root, options.radius_m, options.feet * height_m,
                 [&](const Eigen::Vector3d&) { return ++count >= options.min_feet_voxels; });
  return count >= options.min_feet_voxels;
}

double FloorGap(const VoxelHull& hull, const Eigen::Vector3d& root, double height_m,
                const HullLegsOptions& options) {
  if (hull.voxel_size_m <= 0 || !(height_m > 0)) return 0.0;
  // A layer whose bottom lies at half the height or above has its centre
  // half a voxel higher: such layers are not visited.
  double gap = 0.0;
  VisitLowVoxels(hull, root, options.radius_m, 0.5 * height_m + 0.5 * hull.voxel_size_m,
                 [&](const Eigen::Vector3d& c) {
                   gap = std::max(0.0, c.z() - 0.5 * hull.voxel_size_m);
                   return true;
                 });
  return gap;
}

std::optional<double> HullColumnTop(const VoxelHull& hull, const Eigen::Vector2d& xy, double from_z,
                                    double radius_m) {
  if (hull.voxel_size_m <= 0 || hull.nz <= 0) return std::nullopt;
  const double size = hull.voxel_size_m;
  const int z0 = static_cast<int>(std::floor((from_z - hull.origin_m.z()) / size));
  if (z0 < 0 || z0 >= hull.nz) return std::nullopt;
  const pose_internal::HullColumn column(hull, xy, radius_m);
  if (!column.LayerHolds(z0)) return std::nullopt;
  int z = z0;
  while (z + 1 < hull.nz && column.LayerHolds(z + 1)) ++z;
  return hull.origin_m.z() + (z + 1) * size;
}

}  // namespace irbench
