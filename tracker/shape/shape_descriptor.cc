#include "tracker/shape/shape_descriptor.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <mutex>
#include <numbers>
#include <opencv2/core/utility.hpp>
#include <stdexcept>

#include "common/error.h"

namespace irbench {
namespace {

// Blurs `h` (dims[0] x dims[1] x dims[2], C order) along `axis` with
// `kernel` (odd length, centred); `circular`: the axis wraps, else what
// falls beyond the edges is dropped.
void BlurAxis(std::vector<double>& h, const std::array<int, 3>& dims, int axis, const std::vector<double>& kernel,
              bool circular) {
  const int n = dims[axis], half = static_cast<int>(kernel.size()) / 2;
  const int stride = axis == 2 ? 1 : axis == 1 ? dims[2] : dims[1] * dims[2];
  std::vector<double> line(n), out(n);
  for (int a = 0; a < dims[0]; ++a) {
    for (int b = 0; b < dims[1]; ++b) {
      for (int c = 0; c < dims[2]; ++c) {
        const int coord = axis == 0 ? a : axis == 1 ? b : c;
        if (coord != 0) continue;  // one line per start
        const size_t base = (static_cast<size_t>(a) * dims[1] + b) * dims[2] + c;
        for (int i = 0; i < n; ++i) line[i] = h[base + static_cast<size_t>(i) * stride];
        for (int i = 0; i < n; ++i) {
          double v = 0;
          for (int o = -half; o <= half; ++o) {
            int j = i + o;
            if (circular) {
              j = ((j % n) + n) % n;
            } else if (j < 0 || j >= n) {
              continue;
            }
            v += kernel[o + half] * line[j];
          }
          out[i] = v;
        }
        for (int i = 0; i < n; ++i) h[base + static_cast<size_t>(i) * stride] = out[i];
      }
    }
  }
}

}  // namespace

void ShapeDescriptorOptions::Check() const {
  auto positive = [](int v, int hi, const char* field) {
    if (v < 1 || v > hi) throw InputError("", field, "must be in 1.." + std::to_string(hi));
  };
  positive(rings, 64, "rings");
  positive(azimuths, 256, "azimuths");
  positive(r_bins, 256, "r_bins");
  positive(theta_bins, 256, "theta_bins");
  positive(phi_bins, 256, "phi_bins");
  positive(max_points, 1 << 24, "max_points");
  if (!(smoothing_bins >= 0 && smoothing_bins <= 4)) throw InputError("", "smoothing_bins", "must be in 0..4");
  if (!(radius_per_height > 0 && radius_per_height <= 2)) {
    throw InputError("", "radius_per_height", "must be in (0, 2]");
  }
}

int ShapeDescriptor::NonEmptyBins() const {
  return static_cast<int>(std::count_if(bins.begin(), bins.end(), [](float b) { return b > 0; }));
}

std::vector<Eigen::Vector3d> HullSurfacePoints(const VoxelHull& hull) {
  std::vector<Eigen::Vector3d> points;
  if (hull.occupied_count == 0) return points;
  std::array<int, 6> box = hull.occupied_within.value_or(std::array<int, 6>{0, 0, 0, hull.nx, hull.ny, hull.nz});
  auto occupied = [&](int x, int y, int z) {
    return x >= 0 && y >= 0 && z >= 0 && x < hull.nx && y < hull.ny && z < hull.nz && hull.Occupied(x, y, z);
  };
  for (int z = box[2]; z < box[5]; ++z) {
    for (int y = box[1]; y < box[4]; ++y) {
      for (int x = box[0]; x < box[3]; ++x) {
        if (!hull.Occupied(x, y, z)) continue;
        if (occupied(x - 1, y, z) && occupied(x + 1, y, z) && occupied(x, y - 1, z) && occupied(x, y + 1, z) &&
            occupied(x, y, z - 1) && occupied(x, y, z + 1)) {
          continue;
        }
        points.push_back(hull.VoxelCenter(x, y, z));
      }
    }
  }
  return points;
}

ShapeDescriptor ComputeShapeDescriptor(const std::vector<Eigen::Vector3d>& points_in_world, double height_m,
                                       const ShapeDescriptorOptions& options) {
  options.Check();
  if (!(height_m > 0) || !std::isfinite(height_m)) throw std::invalid_argument("the user's height must be > 0");
  ShapeDescriptor out;
  out.height_m = height_m;
  std::vector<uint32_t> counts(options.bin_count(), 0);
  if (points_in_world.empty()) {
    out.bins.assign(counts.size(), 0.0f);
    return out;
  }
  // An even stride through the points, at most max_points of them.
  const size_t n = points_in_world.size();
  const size_t used = std::min<size_t>(n, options.max_points);
  std::vector<Eigen::Vector3f> points(used);
  Eigen::Vector2d centroid = Eigen::Vector2d::Zero();
  for (size_t i = 0; i < used; ++i) {
    points[i] = points_in_world[i * n / used].cast<float>();
    centroid += points[i].head<2>().cast<double>();
  }
  centroid /= static_cast<double>(used);
  out.axis_xy = centroid;
  out.point_count = static_cast<int>(used);
  for (auto& p : points) p.head<2>() -= centroid.cast<float>();

  const double radius = options.radius_per_height * height_m;
  const float inv_diag = static_cast<float>(1.0 / std::hypot(2 * radius, height_m));
  const int kr = options.r_bins, kt = options.theta_bins, kp = options.phi_bins;
  // Theta's bin edges as cosines (theta = l pi / L, cos decreasing): bin l
  // holds cos in (cos_edge[l + 1], cos_edge[l]].
  std::vector<float> cos_edge(kt + 1);
  for (int l = 0; l <= kt; ++l) cos_edge[l] = static_cast<float>(std::cos(l * std::numbers::pi / kt));
  const float phi_scale = static_cast<float>(kp / (2 * std::numbers::pi));
  // The reference points in parallel, each range counting into its own
  // histogram; integer counts sum to the same bytes however it is split.
  std::mutex merge;
  cv::parallel_for_(cv::Range(0, options.rings * options.azimuths), [&](const cv::Range& range) {
    std::vector<uint32_t> local(counts.size(), 0);
    for (int reference = range.start; reference < range.end; ++reference) {
      const int ring = reference / options.azimuths, a = reference % options.azimuths;
      const float z_ring = static_cast<float>((ring + 0.5) * height_m / options.rings);
      const double alpha = 2 * std::numbers::pi * a / options.azimuths;
      const Eigen::Vector2f normal(static_cast<float>(std::cos(alpha)), static_cast<float>(std::sin(alpha)));
      const Eigen::Vector2f tangent(-normal.y(), normal.x());
      const Eigen::Vector2f q = static_cast<float>(radius) * normal;
      for (const Eigen::Vector3f& p : points) {
        const Eigen::Vector2f d_xy = p.head<2>() - q;
        const float dn = d_xy.dot(normal), dt = d_xy.dot(tangent), dz = p.z() - z_ring;
        const float length = std::sqrt(dn * dn + dt * dt + dz * dz);
        const int k = std::min(static_cast<int>(length * inv_diag * kr), kr - 1);
        const float c = length > 0 ? dz / length : 1.0f;
        // The first edge below c: theta's bin (c = 1 is bin 0).
        const int l = std::clamp(static_cast<int>(std::upper_bound(cos_edge.begin(), cos_edge.end(), c,
                                                                   [](float v, float e) { return v > e; }) -
                                                  cos_edge.begin()) - 1,
                                 0, kt - 1);
        // Bins centred on phi = j 2 pi / P: inward (phi = +-pi) is one bin.
        int pb = static_cast<int>(std::floor(std::atan2(dt, dn) * phi_scale + 0.5f));
        pb = ((pb % kp) + kp) % kp;
        ++local[(static_cast<size_t>(k) * kt + l) * kp + pb];
      }
    }
    const std::lock_guard<std::mutex> lock(merge);
    for (size_t i = 0; i < counts.size(); ++i) counts[i] += local[i];
  }, std::max(1, cv::getNumThreads()));  // one histogram per thread, not per reference point
  std::vector<double> h(counts.begin(), counts.end());
  if (options.smoothing_bins > 0) {
    std::vector<double> kernel;
    for (int o = -3; o <= 3; ++o) kernel.push_back(std::exp(-0.5 * o * o / (options.smoothing_bins * options.smoothing_bins)));
    double sum = 0;
    for (double k : kernel) sum += k;
    for (double& k : kernel) k /= sum;
    const std::array<int, 3> dims = {kr, kt, kp};
    BlurAxis(h, dims, 0, kernel, false);
    BlurAxis(h, dims, 1, kernel, false);
    BlurAxis(h, dims, 2, kernel, true);
  }
  const double largest = *std::max_element(h.begin(), h.end());
  out.bins.resize(h.size());
  for (size_t i = 0; i < h.size(); ++i) {
    // Below 1e-6 of the largest bin is empty (the blur's far tails).
    out.bins[i] = h[i] > 1e-6 * largest ? static_cast<float>(h[i] / largest) : 0.0f;
  }
  return out;
}

ShapeDescriptor HullShapeDescriptor(const VoxelHull& hull, double height_m, const ShapeDescriptorOptions& options) {
  return ComputeShapeDescriptor(HullSurfacePoints(hull), height_m, options);
}

}  // namespace irbench
