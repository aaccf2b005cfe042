#include "tracker/hull/voxel_hull.h"

#include <algorithm>
#include <atomic>
#include <climits>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <mutex>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <utility>

#include "common/error.h"

namespace irbench {
namespace {

// The largest std::hypot(du[i], dv[i]) over i < n (0 for none; a NaN ignored
// as std::max ignores it), with one hypot per near-largest pair instead of
// one per pair (a voxel carver's set-up called it tens of millions of times).
// hypot is within an ulp of the true length and the squared length within
// three of its square, so a pair whose squared length lies a relative 1e-9
// under the largest has a strictly smaller hypot than that pair: the result
// is the same double as taking every hypot.
template <typename Pair>
double MaxHypot(size_t n, const Pair& pair) {
  double max_sq = 0;
  for (size_t i = 0; i < n; ++i) {
    const auto [du, dv] = pair(i);
    max_sq = std::max(max_sq, du * du + dv * dv);
  }
  const double below = max_sq * (1 - 1e-9);
  double result = 0;
  for (size_t i = 0; i < n; ++i) {
    const auto [du, dv] = pair(i);
    if (!(du * du + dv * dv < below)) result = std::max(result, std::hypot(du, dv));
  }
  return result;
}

}  // namespace

void VoxelGridOptions::Check() const {
  if (!(voxel_size_m > 0)) throw InputError("", "voxels.voxel_size_m", "must be > 0");
  if (max_missing_views < 0 || max_missing_views > 8) throw InputError("", "voxels.max_missing_views", "must be in 0..8");
  for (int a = 0; a < 3; ++a) {
    if (!(max_corner_m[a] > min_corner_m[a]))
      throw InputError("", "voxels.max_corner_m", "must exceed min_corner_m on every axis");
  }
  const Eigen::Vector3d n = (max_corner_m - min_corner_m) / voxel_size_m;
  if (n.x() * n.y() * n.z() > 4.0e8)
    throw InputError("", "voxels.voxel_size_m", "grid too large (over 4e8 voxels)");
  if (margin_px < 0 || margin_px > 100) throw InputError("", "voxels.margin_px", "must be in [0, 100]");
  if (footprint_scale < 0 || footprint_scale > 4)
    throw InputError("", "voxels.footprint_scale", "must be in [0, 4]");
  if (min_observing_cameras < 1) throw InputError("", "voxels.min_observing_cameras", "must be >= 1");
  if (max_missing_views >= min_observing_cameras) {
    // Else a voxel seen by just min_observing_cameras cameras could never be carved.
    throw InputError("", "voxels.max_missing_views", "must be below min_observing_cameras (" +
                                                  std::to_string(min_observing_cameras) + ")");
  }
  if (!(near_m > 0)) throw InputError("", "voxels.near_m", "must be > 0");
}

bool VoxelHull::ContainsPoint(const Eigen::Vector3d& p_in_world) const {
  const Eigen::Vector3d g = (p_in_world - origin_m) / voxel_size_m;
  const int x = static_cast<int>(std::floor(g.x()));
  const int y = static_cast<int>(std::floor(g.y()));
  const int z = static_cast<int>(std::floor(g.z()));
  if (x < 0 || y < 0 || z < 0 || x >= nx || y >= ny || z >= nz) return false;
  return Occupied(x, y, z);
}

Eigen::Vector3d VoxelHull::VoxelCenter(int x, int y, int z) const {
  return origin_m + voxel_size_m * Eigen::Vector3d(x + 0.5, y + 0.5, z + 0.5);
}

double VoxelHull::VolumeM3() const {
  return occupied_count * voxel_size_m * voxel_size_m * voxel_size_m;
}

std::vector<Eigen::Vector3d> VoxelHull::OccupiedCenters() const {
  std::vector<Eigen::Vector3d> out;
  out.reserve(occupied_count);
  // In index order (z, then y, then x), each row's run within the box
  // skipping empty voxels 8 at a time.
  const std::array<int, 6> box = occupied_within.value_or(std::array<int, 6>{0, 0, 0, nx, ny, nz});
  const uint8_t* o = occupied.data();
  for (int z = std::max(0, box[2]); z < std::min(nz, box[5]); ++z) {
    for (int y = std::max(0, box[1]); y < std::min(ny, box[4]); ++y) {
      const size_t row = (size_t(z) * ny + y) * nx;
      const int end = std::min(nx, box[3]);
      for (int x = std::max(0, box[0]); x < end;) {
        if (x + 8 <= end) {
          uint64_t word;
          std::memcpy(&word, o + row + x, 8);
          if (word == 0) {
            x += 8;
            continue;
          }
        }
        if (o[row + x]) out.push_back(VoxelCenter(x, y, z));
        ++x;
      }
    }
  }
  return out;
}

VoxelCarver::VoxelCarver(std::vector<Camera> cameras, const VoxelGridOptions& options)
    : cameras_(std::move(cameras)), options_(options) {
  options_.Check();
  if (cameras_.empty()) throw InputError("", "cameras", "no cameras");
  const double s = options_.voxel_size_m;
  const Eigen::Vector3d extent = options_.max_corner_m - options_.min_corner_m;
  nx_ = std::max(1, static_cast<int>(std::ceil(extent.x() / s - 1e-9)));
  ny_ = std::max(1, static_cast<int>(std::ceil(extent.y() / s - 1e-9)));
  nz_ = std::max(1, static_cast<int>(std::ceil(extent.z() / s - 1e-9)));
  // The counts of pass 1 are freed once the candidates are grouped.
  GroupCandidates(CountObservingCameras());
  ComputeFootprints();
  ComputeBounds();
}

Eigen::Vector3d VoxelCarver::VoxelCentre(size_t v) const {
  const double s = options_.voxel_size_m;
  const int x = static_cast<int>(v % nx_), y = static_cast<int>((v / nx_) % ny_),
            z = static_cast<int>(v / nx_ / ny_);
  return Eigen::Vector3d(options_.min_corner_m + s * Eigen::Vector3d(x + 0.5, y + 0.5, z + 0.5));
}

std::vector<uint8_t> VoxelCarver::CountObservingCameras() const {
  const size_t voxels = size_t(nx_) * ny_ * nz_;
  const size_t nc = cameras_.size();
  // Pass 1: which voxels enough cameras observe (centre in front and in the image).
  std::vector<uint8_t> observed(voxels, 0);
  for (size_t c = 0; c < nc; ++c) {
    const Camera& cam = cameras_[c];
    if (cam.width <= 1 || cam.height <= 1 || cam.width > 32767 || cam.height > 32767) {
      throw InputError("", "cameras[" + std::to_string(c) + "].width", "bad image size");
    }
    for (size_t v = 0; v < voxels; ++v) {
      const Eigen::Vector3d centre = VoxelCentre(v);
      const Eigen::Vector3d centre_in_cam = cam.cam_from_world * centre;
      if (centre_in_cam.z() <= options_.near_m) continue;
      const Eigen::Vector2d pc = cam.ProjectInCamera(centre_in_cam);
      if (pc.x() >= -0.5 && pc.y() >= -0.5 && pc.x() <= cam.width - 0.5 &&
          pc.y() <= cam.height - 0.5)
        ++observed[v];
    }
  }
  return observed;
}

void VoxelCarver::GroupCandidates(const std::vector<uint8_t>& observed) {
  const size_t voxels = size_t(nx_) * ny_ * nz_;
  // The candidates, grouped by block, within it by sub-block and within that
  // by cell (counting sort on the triple; within a cell in voxel index order).
  const int bx = (nx_ + kBlock - 1) / kBlock, by = (ny_ + kBlock - 1) / kBlock,
            bz = (nz_ + kBlock - 1) / kBlock;
  // Keys: block, then its octant (sub-block), then the octant's octant (cell).
  constexpr int kSub = kBlock / 2, kCell = kBlock / 4;
  auto key_of = [&](size_t v) {
    const int x = static_cast<int>(v % nx_), y = static_cast<int>((v / nx_) % ny_),
              z = static_cast<int>(v / nx_ / ny_);
    const size_t block = (size_t(z / kBlock) * by + y / kBlock) * bx + x / kBlock;
    const int sub = ((z % kBlock) / kSub * 2 + (y % kBlock) / kSub) * 2 + (x % kBlock) / kSub;
    const int cell = ((z % kSub) / kCell * 2 + (y % kSub) / kCell) * 2 + (x % kSub) / kCell;
    return (block * 8 + sub) * 8 + cell;
  };
  const size_t n_keys = size_t(bx) * by * bz * 64;
  std::vector<uint32_t> per_block(n_keys + 1, 0);  // per key, then its start
  for (size_t v = 0; v < voxels; ++v) {
    if (observed[v] >= options_.min_observing_cameras) ++per_block[key_of(v) + 1];
  }
  size_t last_block = SIZE_MAX, last_sub = SIZE_MAX;
  for (size_t key = 0; key < n_keys; ++key) {
    const uint32_t count = per_block[key + 1];
    per_block[key + 1] += per_block[key];
    if (count == 0) continue;
    if (key / 64 != last_block) {
      last_block = key / 64;
      blocks_.push_back(
          {per_block[key], 0, static_cast<uint32_t>(sub_blocks_.size()), 0, static_cast<uint32_t>(last_block)});
    }
    if (key / 8 != last_sub) {
      last_sub = key / 8;
      sub_blocks_.push_back({per_block[key], 0, static_cast<uint32_t>(cells_.size()), 0, 0});
      ++blocks_.back().sub_count;
    }
    cells_.push_back({per_block[key], count, 0, 0, 0});
    ++sub_blocks_.back().sub_count;
    sub_blocks_.back().count += count;
    blocks_.back().count += count;
  }
  candidates_.resize(per_block.back());
  for (size_t v = 0; v < voxels; ++v) {
    if (observed[v] >= options_.min_observing_cameras)
      candidates_[per_block[key_of(v)]++] = static_cast<uint32_t>(v);
  }
}

void VoxelCarver::ComputeFootprints() {
  const double s = options_.voxel_size_m;
  const int lx = nx_ + 1, ly = ny_ + 1, lz = nz_ + 1;
  const size_t lattice = size_t(lx) * ly * lz;
  const size_t nc = cameras_.size();
  // Pass 2, per camera: the footprint of every candidate, from the projected
  // lattice corners (each shared by up to 8 voxels). The cameras run in
  // parallel, each with its own projected lattice (9 bytes a lattice point)
  // and writing only its own footprints: the same bytes on any thread count.
  const size_t nk = candidates_.size();
  footprints_.assign(nk * nc, Footprint{-1, 0, 0, 0});
  const double m = options_.margin_px;
  cv::parallel_for_(cv::Range(0, static_cast<int>(nc)), [&](const cv::Range& range) {
    std::vector<float> lu(lattice), lv(lattice);
    std::vector<uint8_t> lok(lattice);
    for (size_t c = range.start; c < static_cast<size_t>(range.end); ++c) {
      const Camera& cam = cameras_[c];
      for (int z = 0; z < lz; ++z) {
        for (int y = 0; y < ly; ++y) {
          for (int x = 0; x < lx; ++x) {
            const size_t i = (size_t(z) * ly + y) * lx + x;
            const Eigen::Vector3d p = options_.min_corner_m + s * Eigen::Vector3d(x, y, z);
            const Eigen::Vector3d p_in_cam = cam.cam_from_world * p;
            lok[i] = p_in_cam.z() > options_.near_m;
            if (lok[i]) {
              const Eigen::Vector2d px = cam.ProjectInCamera(p_in_cam);
              lu[i] = static_cast<float>(px.x());
              lv[i] = static_cast<float>(px.y());
            }
          }
        }
      }
      const int w = cam.width, h = cam.height;
      for (size_t k = 0; k < nk; ++k) {
        const size_t v = candidates_[k];
        const int x = static_cast<int>(v % nx_), y = static_cast<int>((v / nx_) % ny_),
                  z = static_cast<int>(v / nx_ / ny_);
        size_t corner_index[8];
        bool ok = true;
        for (int corner = 0; corner < 8; ++corner) {
          corner_index[corner] =
              (size_t(z + (corner >> 2)) * ly + y + ((corner >> 1) & 1)) * lx + x + (corner & 1);
          ok = ok && lok[corner_index[corner]];
        }
        if (!ok) continue;  // partly behind the camera: no constraint
        const Eigen::Vector2d pc = cam.Project(VoxelCentre(v));
        const double corner_radius = MaxHypot(8, [&](size_t i) {
          return std::pair<double, double>(lu[corner_index[i]] - pc.x(), lv[corner_index[i]] - pc.y());
        });
        const double radius = options_.footprint_scale * corner_radius + m;
        // The disk partly outside the image: the camera cannot rule the voxel out.
        if (pc.x() - radius < -0.5 || pc.y() - radius < -0.5 || pc.x() + radius > w - 0.5 ||
            pc.y() + radius > h - 0.5) {
          continue;
        }
        // Bilinear interpolation reads the pixel right of and below the floor.
        const double fu = std::clamp(pc.x(), 0.0, w - 1.001), fv = std::clamp(pc.y(), 0.0, h - 1.001);
        const int u0 = static_cast<int>(fu), v0 = static_cast<int>(fv);
        Footprint& f = footprints_[k * nc + c];
        f.pixel = v0 * w + u0;
        f.frac_u = static_cast<uint8_t>(std::min(255.0, std::round((fu - u0) * 256)));
        f.frac_v = static_cast<uint8_t>(std::min(255.0, std::round((fv - v0) * 256)));
        f.radius_q = static_cast<uint16_t>(std::min(65535.0, std::floor(radius * 64)));
      }
    }
  });
}

// Per block and camera: the bounds. Each voxel's test value is the bilinear
// interpolation of D at its point q (pixel + frac / 256), at least the least
// and at most the greatest of D at the 4 pixel centres around q, each
// within sqrt(2) of q. With all q of the block within rho of a point U and g
// the pixel centre nearest U, D being 1-Lipschitz bounds all these values by
// D[g] -+ (sqrt(2) + rho + |U - g|). The float arithmetic of the test and
// of the transform adds error far below kSlackPx.
VoxelCarver::BlockBound VoxelCarver::BoundOf(const Block& block, size_t c) const {
  constexpr double kSlackPx = 0.01;
  constexpr float kInf = std::numeric_limits<float>::infinity();
  const size_t nc = cameras_.size();
  const int w = cameras_[c].width, h = cameras_[c].height;
  double u_lo = 1e30, u_hi = -1e30, v_lo = 1e30, v_hi = -1e30, r_lo = 1e30, r_hi = 0;
  bool all_constrained = true;
  for (uint32_t k = block.first; k < block.first + block.count; ++k) {
    const Footprint& f = footprints_[size_t(k) * nc + c];
    if (f.pixel < 0) {
      all_constrained = false;
      continue;
    }
    const double u = f.pixel % w + f.frac_u / 256.0, v = f.pixel / w + f.frac_v / 256.0;
    u_lo = std::min(u_lo, u);
    u_hi = std::max(u_hi, u);
    v_lo = std::min(v_lo, v);
    v_hi = std::max(v_hi, v);
    r_lo = std::min(r_lo, f.radius_q / 64.0);
    r_hi = std::max(r_hi, f.radius_q / 64.0);
  }
  if (u_lo > u_hi) return {0, kInf, kInf};  // no voxel of the block is constrained: all pass
  const double cu = 0.5 * (u_lo + u_hi), cv = 0.5 * (v_lo + v_hi);
  const int gu = std::clamp(static_cast<int>(std::lround(cu)), 0, w - 1),
            gv = std::clamp(static_cast<int>(std::lround(cv)), 0, h - 1);
  // Unconstrained voxels (pixel < 0) count as the centre itself.
  const double rho = MaxHypot(block.count, [&](size_t i) {
    const Footprint& f = footprints_[size_t(block.first + i) * nc + c];
    return f.pixel < 0 ? std::pair<double, double>(0, 0)
                       : std::pair<double, double>(f.pixel % w + f.frac_u / 256.0 - cu,
                                                   f.pixel / w + f.frac_v / 256.0 - cv);
  });
  const double reach = std::sqrt(2.0) + rho + std::hypot(cu - gu, cv - gv) + kSlackPx;
  // Voxels without a constraint pass, so only a fully constrained block
  // can be carved whole.
  return {gv * w + gu, all_constrained ? static_cast<float>(r_hi + reach) : kInf,
          static_cast<float>(r_lo - reach)};
}

void VoxelCarver::ComputeBounds() {
  const size_t nc = cameras_.size();
  // Each level's blocks in parallel (every bound is written once).
  const auto bound_all = [&](const std::vector<Block>& blocks, std::vector<BlockBound>* bounds) {
    bounds->resize(blocks.size() * nc);
    cv::parallel_for_(cv::Range(0, static_cast<int>(blocks.size())), [&](const cv::Range& range) {
      for (int b = range.start; b < range.end; ++b) {
        for (size_t c = 0; c < nc; ++c) (*bounds)[b * nc + c] = BoundOf(blocks[b], c);
      }
    });
  };
  bound_all(blocks_, &bounds_);
  bound_all(sub_blocks_, &sub_bounds_);
  bound_all(cells_, &cell_bounds_);
}

cv::Mat DistanceToSilhouette(const cv::Mat& silhouette) {
  CV_Assert(silhouette.type() == CV_8UC1);
  const int w = silhouette.cols, h = silhouette.rows;
  // Felzenszwalb and Huttenlocher's exact transform, as cv::distanceTransform
  // (DIST_L2, DIST_MASK_PRECISE) computes it, with the same values: per
  // column the distance to the nearest silhouette pixel of that column, then
  // per row the lower envelope of the parabolas (x - q)^2 + g(q)^2. Only the
  // columns that hold silhouette pixels have parabolas, so for a body in a
  // fraction of the image the rows cost a fraction of theirs.
  constexpr int kFar = 1 << 20;
  cv::Mat1i column(h, w);
  std::vector<uint8_t> has_silhouette(w, 0);
  for (int y = 0; y < h; ++y) {
    const uint8_t* sp = silhouette.ptr<uint8_t>(y);
    int* g = column[y];
    const int* above = y > 0 ? column[y - 1] : nullptr;
    for (int x = 0; x < w; ++x) {
      const bool in = sp[x] > 127;
      g[x] = in ? 0 : above ? std::min(kFar, above[x] + 1) : kFar;
      has_silhouette[x] |= in;
    }
  }
  for (int y = h - 2; y >= 0; --y) {
    int* g = column[y];
    const int* below = column[y + 1];
    for (int x = 0; x < w; ++x) g[x] = std::min(g[x], below[x] + 1);
  }
  std::vector<int> columns;
  for (int x = 0; x < w; ++x) {
    if (has_silhouette[x]) columns.push_back(x);
  }
  if (columns.empty()) return cv::Mat(silhouette.size(), CV_32F, cv::Scalar(1e6));  // no silhouette: all far
  cv::Mat out(silhouette.size(), CV_32F);
  std::vector<int> v(columns.size());          // the envelope's parabolas, by column
  std::vector<double> z(columns.size() + 1);  // where each takes over
  for (int y = 0; y < h; ++y) {
    const int* g = column[y];
    auto f = [&](int q) { return static_cast<double>(g[q]) * g[q] + static_cast<double>(q) * q; };
    int k = 0;
    v[0] = columns[0];
    z[0] = -std::numeric_limits<double>::infinity();
    z[1] = std::numeric_limits<double>::infinity();
    for (size_t i = 1; i < columns.size(); ++i) {
      const int q = columns[i];
      double s = (f(q) - f(v[k])) / (2.0 * (q - v[k]));
      while (s <= z[k]) {
        --k;
        s = (f(q) - f(v[k])) / (2.0 * (q - v[k]));
      }
      ++k;
      v[k] = q;
      z[k] = s;
      z[k + 1] = std::numeric_limits<double>::infinity();
    }
    // The squared distances (integers, exact in float); their roots below,
    // all at once.
    // Parabola j holds the columns x with z[j] < x <= z[j + 1].
    float* op = out.ptr<float>(y);
    int x = 0;
    for (int j = 0; j <= k && x < w; ++j) {
      const int last = z[j + 1] >= w - 1 ? w - 1 : static_cast<int>(std::floor(z[j + 1]));
      const int q = v[j], gy2 = g[q] * g[q];
      for (; x <= last; ++x) op[x] = static_cast<float>((x - q) * (x - q) + gy2);
    }
  }
  // cv::sqrt runs vectorised; IEEE square roots are correctly rounded, so
  // the values are those of std::sqrt per pixel.
  cv::sqrt(out, out);
  return out;
}

std::vector<cv::Mat> VoxelCarver::DistanceTransforms(const std::vector<cv::Mat>& silhouettes) const {
  const size_t nc = cameras_.size();
  if (silhouettes.size() != nc) {
    throw InputError("", "silhouettes",
                     "expected " + std::to_string(nc) + " silhouettes, got " +
                         std::to_string(silhouettes.size()));
  }
  std::vector<cv::Mat> out(nc);
  for (size_t c = 0; c < nc; ++c) {
    const cv::Mat& sil = silhouettes[c];
    if (sil.type() != CV_8UC1 || sil.cols != cameras_[c].width || sil.rows != cameras_[c].height) {
      throw InputError("", "silhouettes[" + std::to_string(c) + "]",
                       "must be CV_8UC1 of the camera's size");
    }
    out[c] = DistanceToSilhouette(sil);
  }
  return out;
}

VoxelHull VoxelCarver::EmptyHull() const {
  VoxelHull hull;
  hull.origin_m = options_.min_corner_m;
  hull.voxel_size_m = options_.voxel_size_m;
  hull.nx = nx_;
  hull.ny = ny_;
  hull.nz = nz_;
  hull.occupied.assign(size_t(nx_) * ny_ * nz_, 0);
  return hull;
}

namespace {

// The per-voxel test (thesis 4.2): the distance transform `dist` (row stride
// `w`), bilinearly interpolated at the footprint's point, is at most its radius.
template <typename Footprint>
inline bool Passes(const float* dist, int w, const Footprint& f) {
  if (f.pixel < 0) return true;
  const float* d = dist + f.pixel;
  const float fu = f.frac_u * (1.0f / 256), fv = f.frac_v * (1.0f / 256);
  const float top = d[0] + fu * (d[1] - d[0]);
  const float bottom = d[w] + fu * (d[w + 1] - d[w]);
  return top + fv * (bottom - top) <= f.radius_q * (1.0f / 64);
}

}  // namespace

VoxelHull VoxelCarver::Carve(const std::vector<cv::Mat>& silhouettes) const {
  return CarveDistances(DistanceTransforms(silhouettes));
}

VoxelHull VoxelCarver::CarveDistances(const std::vector<cv::Mat>& distances) const {
  const size_t nc = cameras_.size();
  if (distances.size() != nc) {
    throw InputError("", "distances",
                     "expected " + std::to_string(nc) + " distance transforms, got " +
                         std::to_string(distances.size()));
  }
  std::vector<const float*> dist(nc);
  std::vector<int> width(nc), all_cameras(nc);
  for (size_t c = 0; c < nc; ++c) {
    const cv::Mat& d = distances[c];
    if (d.type() != CV_32FC1 || d.cols != cameras_[c].width || d.rows != cameras_[c].height || !d.isContinuous()) {
      throw InputError("", "distances[" + std::to_string(c) + "]",
                       "must be a continuous CV_32FC1 of the camera's size");
    }
    dist[c] = d.ptr<float>();
    width[c] = cameras_[c].width;
    all_cameras[c] = static_cast<int>(c);
  }
  VoxelHull hull = EmptyHull();
  const int allowed = options_.max_missing_views;
  std::atomic<int> occupied{0};
  // Blocks write disjoint voxels: ranges of them run in parallel.
  const int n_blocks = static_cast<int>(blocks_.size());
  // The box of the blocks holding occupied voxels, in blocks: {x0, y0, z0,
  // x1, y1, z1}, inclusive.
  const int bx = (nx_ + kBlock - 1) / kBlock, by = (ny_ + kBlock - 1) / kBlock;
  std::array<int, 6> block_box = {INT_MAX, INT_MAX, INT_MAX, -1, -1, -1};
  std::mutex box_mutex;
  // The levels of groups, coarse to fine: blocks, their octants (sub-blocks),
  // and those octants' octants (cells of 2x2x2 voxels).
  const std::array<const std::vector<Block>*, 3> groups = {&blocks_, &sub_blocks_, &cells_};
  const std::array<const std::vector<BlockBound>*, 3> group_bounds = {&bounds_, &sub_bounds_, &cell_bounds_};
  cv::parallel_for_(cv::Range(0, n_blocks), [&](const cv::Range& range) {
    std::array<std::vector<int>, 3> unsure;  // per level, the cameras still to consult
    for (std::vector<int>& u : unsure) u.resize(nc);
    int count = 0;
    std::array<int, 6> box = {INT_MAX, INT_MAX, INT_MAX, -1, -1, -1};
    // Group g of `level`, in the cameras `cams` (the coarser level's unsure
    // ones; `misses` already carve it): skipped when more than `allowed`
    // cameras carve it all by its bounds, filled when none is unsure of it,
    // else its finer groups (or, for a cell, its voxels) judged the same way.
    auto visit = [&](auto& self, int level, uint32_t g, const int* cams, int n_cams, int misses) -> void {
      const BlockBound* bound = group_bounds[level]->data() + size_t(g) * nc;
      int* left = unsure[level].data();
      int n_left = 0;
      for (int i = 0; i < n_cams; ++i) {
        const int c = cams[i];
        const float d = dist[c][bound[c].pixel];
        if (d > bound[c].carve_above) {
          ++misses;
        } else if (!(d <= bound[c].keep_below)) {
          left[n_left++] = c;
        }
      }
      if (misses > allowed) return;
      const Block& group = (*groups[level])[g];
      const uint32_t end = group.first + group.count;
      if (n_left == 0) {
        for (uint32_t k = group.first; k < end; ++k) hull.occupied[candidates_[k]] = 1;
        count += static_cast<int>(group.count);
        return;
      }
      if (level + 1 < static_cast<int>(groups.size())) {
        for (uint32_t s = group.sub_first; s < group.sub_first + group.sub_count; ++s) {
          self(self, level + 1, s, left, n_left, misses);
        }
        return;
      }
      for (uint32_t k = group.first; k < end; ++k) {
        const Footprint* fp = footprints_.data() + size_t(k) * nc;
        int voxel_misses = misses;
        for (int i = 0; i < n_left && voxel_misses <= allowed; ++i) {
          const int c = left[i];
          voxel_misses += !Passes(dist[c], width[c], fp[c]);
        }
        if (voxel_misses <= allowed) {
          hull.occupied[candidates_[k]] = 1;
          ++count;
        }
      }
    };
    for (int b = range.start; b < range.end; ++b) {
      const int count_before = count;
      visit(visit, 0, static_cast<uint32_t>(b), all_cameras.data(), static_cast<int>(nc), 0);
      if (count == count_before) continue;
      // Block b got occupied voxels: it widens the box.
      const uint32_t index = blocks_[b].index;
      const int at[3] = {int(index % bx), int(index / bx % by), int(index / bx / by)};
      for (int a = 0; a < 3; ++a) {
        box[a] = std::min(box[a], at[a]);
        box[a + 3] = std::max(box[a + 3], at[a]);
      }
    }
    occupied += count;
    std::lock_guard<std::mutex> lock(box_mutex);
    for (int a = 0; a < 3; ++a) {
      block_box[a] = std::min(block_box[a], box[a]);
      block_box[a + 3] = std::max(block_box[a + 3], box[a + 3]);
    }
  }, 64);
  hull.occupied_count = occupied;
  if (block_box[3] < 0) {
    hull.occupied_within = std::array<int, 6>{0, 0, 0, 0, 0, 0};
  } else {
    hull.occupied_within = std::array<int, 6>{block_box[0] * kBlock, block_box[1] * kBlock, block_box[2] * kBlock,
                                              std::min(nx_, (block_box[3] + 1) * kBlock),
                                              std::min(ny_, (block_box[4] + 1) * kBlock),
                                              std::min(nz_, (block_box[5] + 1) * kBlock)};
  }
  return hull;
}

VoxelHull VoxelCarver::CarveReference(const std::vector<cv::Mat>& silhouettes) const {
  const std::vector<cv::Mat> distance = DistanceTransforms(silhouettes);
  VoxelHull hull = EmptyHull();
  const size_t nc = cameras_.size();
  for (size_t k = 0; k < candidates_.size(); ++k) {
    int misses = 0;
    for (size_t c = 0; c < nc; ++c) {
      misses += !Passes(distance[c].ptr<float>(), cameras_[c].width, footprints_[k * nc + c]);
    }
    if (misses <= options_.max_missing_views) {
      hull.occupied[candidates_[k]] = 1;
      ++hull.occupied_count;
    }
  }
  return hull;
}

}  // namespace irbench
