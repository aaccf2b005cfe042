#include "sim/lighting/bounce.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <mutex>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <string_view>

#include "common/atomic_file.h"
#include "common/file_bytes.h"
#include "common/logging.h"
#include "common/paths.h"
#include "common/sha256.h"

namespace irbench {
namespace {

// The renderer's direct light (its fragment shader's formula, in double).
double DirectIrradiance(const IrLight& light, const Eigen::Vector3d& p, const Eigen::Vector3d& n) {
  const Eigen::Vector3d to_light = light.position - p;
  const double dist2 = to_light.squaredNorm();
  if (dist2 <= 0) return 0;
  const Eigen::Vector3d l = to_light / std::sqrt(dist2);
  const double c = (-l).dot(light.direction);
  const double cos_half = std::cos(light.cone_deg * M_PI / 360.0);
  const double a = cos_half - 0.05, b = cos_half + 0.05;
  const double u = std::clamp((c - a) / (b - a), 0.0, 1.0);
  const double cone = u * u * (3 - 2 * u);
  const double lambert = std::max(n.dot(l), 0.0);
  return light.power * cone * lambert / std::max(dist2, 0.25);
}

int Channel(const IrLight& light) { return light.wavelength_nm == 940.0 ? kIlluminator940 : kIlluminator850; }

// Reflectance for each channel; the content light is broadband: the mean.
Eigen::Vector3f ChannelReflectance(const NirReflectance& r) {
  return {r.at_850, r.at_940, 0.5f * (r.at_850 + r.at_940)};
}

// A patch as the gathers read it: plain doubles, so that the inner loops
// compile to straight arithmetic in every build (Eigen's 3-vector expressions
// stay calls under the sanitizers, where they took most of a render test's
// time). The arithmetic, operation for operation and in the same order, is
// Eigen's on the BouncePatch: the same bytes.
struct Emitter {
  double cx, cy, cz;  // centre
  double nx, ny, nz;  // unit normal
  double area;
  double r0, r1, r2;  // radiosity per channel
};

Emitter EmitterOf(const BouncePatch& k) {
  return {k.center.x(), k.center.y(), k.center.z(), k.normal.x(), k.normal.y(), k.normal.z(), k.area,
          static_cast<double>(k.radiosity[0]), static_cast<double>(k.radiosity[1]), static_cast<double>(k.radiosity[2])};
}

// Light from patch `k` onto a point (px, py, pz) facing (qx, qy, qz) (unit;
// cosines clamped). The two faces' signs are checked before the square root
// (most pairs in a room face away or lie in one wall); the arithmetic is the
// same either way.
inline double Transfer(const Emitter& k, double px, double py, double pz, double qx, double qy, double qz) {
  const double dx = k.cx - px, dy = k.cy - py, dz = k.cz - pz;  // point -> patch
  const double toward_p = -(k.nx * dx + k.ny * dy + k.nz * dz), toward_k = qx * dx + qy * dy + qz * dz;
  if (toward_p <= 0 || toward_k <= 0) return 0;
  const double r2 = dx * dx + dy * dy + dz * dz;
  if (r2 <= 1e-12) return 0;
  const double r = std::sqrt(r2);
  const double cos_p = toward_p / r;
  const double cos_x = toward_k / r;
  if (cos_p <= 0 || cos_x <= 0) return 0;
  return k.area * cos_p * cos_x / (M_PI * r2 + k.area);
}

// Whether a patch gives any light (radiosities are never negative).
bool GivesLight(const BouncePatch& p) { return p.radiosity.maxCoeff() > 0; }

}  // namespace

std::vector<BouncePatch> BouncePatches(const TriangleMesh& mesh,
                                       const std::vector<IrLight>& lights,
                                       const BounceOptions& options) {
  std::vector<BouncePatch> patches;
  for (size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
    const MeshVertex& v0 = mesh.vertices[mesh.indices[t]];
    const MeshVertex& v1 = mesh.vertices[mesh.indices[t + 1]];
    const MeshVertex& v2 = mesh.vertices[mesh.indices[t + 2]];
    if (v0.emissive > 0.5f) continue;
    const Eigen::Vector3d a = v0.position.cast<double>(), b = v1.position.cast<double>(),
                          c = v2.position.cast<double>();
    const Eigen::Vector3d cross = (b - a).cross(c - a);
    if (cross.norm() < 1e-12) continue;
    // The surface faces where its vertex normals point (rooms inwards).
    Eigen::Vector3d normal = cross.normalized();
    const Eigen::Vector3d vertex_normal = (v0.normal + v1.normal + v2.normal).cast<double>();
    if (normal.dot(vertex_normal) < 0) normal = -normal;
    const double longest = std::max({(b - a).norm(), (c - b).norm(), (a - c).norm()});
    const int n = std::max(1, static_cast<int>(std::ceil(longest / options.patch_m)));
    const double area = 0.5 * cross.norm() / (n * n);
    // n² similar sub-triangles: (i, j) "up" and, where room, "down" ones.
    auto add = [&](const Eigen::Vector3d& centroid) {
      BouncePatch p;
      p.center = centroid;
      p.normal = normal;
      p.area = area;
      p.reflectance = v0.Reflectance();
      p.content = v0.content;
      patches.push_back(p);
    };
    const Eigen::Vector3d du = (b - a) / n, dv = (c - a) / n;
    for (int i = 0; i < n; ++i) {
      for (int j = 0; i + j < n; ++j) {
        const Eigen::Vector3d o = a + i * du + j * dv;
        add(o + (du + dv) / 3.0);
        if (i + j + 1 < n) add(o + 2.0 * (du + dv) / 3.0);
      }
    }
  }
  // Direct light and content emission, then gathers.
  std::vector<Eigen::Vector3f> direct(patches.size());
  for (size_t k = 0; k < patches.size(); ++k) {
    Eigen::Vector3d e = Eigen::Vector3d::Zero();
    for (const IrLight& light : lights) e[Channel(light)] += DirectIrradiance(light, patches[k].center, patches[k].normal);
    direct[k] = e.cast<float>();
    patches[k].radiosity = ChannelReflectance(patches[k].reflectance).cwiseProduct(direct[k]);
    patches[k].radiosity[kScreenContent] += patches[k].content;
  }
  for (int bounce = 1; bounce < options.bounces; ++bounce) {
    std::vector<Eigen::Vector3f> next(patches.size());
    // Only lit patches are gathered from (a dark one would add exact zeros).
    std::vector<Emitter> lit;
    for (const BouncePatch& k : patches) {
      if (GivesLight(k)) lit.push_back(EmitterOf(k));
    }
    cv::parallel_for_(cv::Range(0, static_cast<int>(patches.size())), [&](const cv::Range& range) {
      for (int j = range.start; j < range.end; ++j) {
        const Eigen::Vector3d& p = patches[j].center;
        const Eigen::Vector3d& n = patches[j].normal;
        const double px = p.x(), py = p.y(), pz = p.z(), qx = n.x(), qy = n.y(), qz = n.z();
        double g0 = 0, g1 = 0, g2 = 0;
        for (const Emitter& k : lit) {
          const double f = Transfer(k, px, py, pz, qx, qy, qz);
          if (f > 0) g0 += f * k.r0, g1 += f * k.r1, g2 += f * k.r2;
        }
        const Eigen::Vector3d gathered(g0, g1, g2);
        next[j] = ChannelReflectance(patches[j].reflectance).cwiseProduct(direct[j] + gathered.cast<float>());
        next[j][kScreenContent] += patches[j].content;
      }
    });
    for (size_t k = 0; k < patches.size(); ++k) patches[k].radiosity = next[k];
  }
  return patches;
}

namespace {

// The last volume computed, with what it was computed from: a suite, a sweep
// or a test renders one scene many times in one process, and the volume
// costs a second or two each time. Equal inputs (bit for bit: the vertices
// are tightly packed floats) give the very same volume.
class LastBounce {
 public:
  std::optional<IrradianceVolume> Find(const TriangleMesh& mesh, const std::vector<IrLight>& lights,
                                       const BounceOptions& options) {
    std::lock_guard lock(mutex_);
    if (!volume_ || !Same(mesh, lights, options)) return std::nullopt;
    return volume_;
  }
  void Keep(const TriangleMesh& mesh, const std::vector<IrLight>& lights, const BounceOptions& options,
            const IrradianceVolume& volume) {
    std::lock_guard lock(mutex_);
    mesh_ = mesh;
    lights_ = lights;
    options_ = options;
    volume_ = volume;
  }

 private:
  bool Same(const TriangleMesh& mesh, const std::vector<IrLight>& lights, const BounceOptions& options) const {
    if (mesh.vertices.size() != mesh_.vertices.size() || mesh.indices != mesh_.indices) return false;
    if (!mesh.vertices.empty() &&
        std::memcmp(mesh.vertices.data(), mesh_.vertices.data(), mesh.vertices.size() * sizeof(MeshVertex)) != 0) {
      return false;
    }
    if (options.patch_m != options_.patch_m || options.grid_m != options_.grid_m || options.bounces != options_.bounces) {
      return false;
    }
    if (lights.size() != lights_.size()) return false;
    for (size_t i = 0; i < lights.size(); ++i) {
      const IrLight &a = lights[i], &b = lights_[i];
      if (a.position != b.position || a.direction != b.direction || a.cone_deg != b.cone_deg || a.power != b.power ||
          a.wavelength_nm != b.wavelength_nm) {
        return false;
      }
    }
    return true;
  }

  std::mutex mutex_;
  TriangleMesh mesh_;
  std::vector<IrLight> lights_;
  BounceOptions options_;
  std::optional<IrradianceVolume> volume_;
};

LastBounce& LastBounceVolume() {
  static LastBounce last;
  return last;
}

IrradianceVolume ComputeBounceVolume(const TriangleMesh& mesh,
                                     const std::vector<IrLight>& lights,
                                     const BounceOptions& options) {
  IrradianceVolume volume;
  std::vector<BouncePatch> patches = BouncePatches(mesh, lights, options);
  // Patches with no light give none.
  patches.erase(std::remove_if(patches.begin(), patches.end(),
                               [](const BouncePatch& p) { return !GivesLight(p); }),
                patches.end());
  if (patches.empty() || mesh.vertices.empty()) return volume;
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300), hi = -lo;
  for (const MeshVertex& v : mesh.vertices) {
    lo = lo.cwiseMin(v.position.cast<double>());
    hi = hi.cwiseMax(v.position.cast<double>());
  }
  volume.spacing = options.grid_m;
  for (int k = 0; k < 3; ++k) {
    volume.dims[k] = std::max(2, static_cast<int>(std::ceil((hi[k] - lo[k]) / options.grid_m - 1e-9)) + 1);
  }
  // Centre the grid on the bounds.
  volume.origin = 0.5 * (lo + hi) - 0.5 * options.grid_m * (volume.dims.cast<double>() - Eigen::Vector3d::Ones());
  const int nx = volume.dims.x(), ny = volume.dims.y(), nz = volume.dims.z();
  const size_t points = size_t(nx) * ny * nz;
  volume.values.assign(6 * points, Eigen::Vector3f::Zero());
  std::vector<Emitter> emitters;
  emitters.reserve(patches.size());
  for (const BouncePatch& k : patches) emitters.push_back(EmitterOf(k));
  cv::parallel_for_(cv::Range(0, static_cast<int>(points)), [&](const cv::Range& range) {
    for (int i = range.start; i < range.end; ++i) {
      const int x = i % nx, y = (i / nx) % ny, z = i / (nx * ny);
      const Eigen::Vector3d p = volume.origin + options.grid_m * Eigen::Vector3d(x, y, z);
      const double px = p.x(), py = p.y(), pz = p.z();
      // e[dir][channel], dir = +x, -x, +y, -y, +z, -z.
      double e[6][3] = {};
      for (const Emitter& k : emitters) {
        const double d[3] = {k.cx - px, k.cy - py, k.cz - pz};
        const double toward_p = -(k.nx * d[0] + k.ny * d[1] + k.nz * d[2]);
        if (toward_p <= 0) continue;  // p behind the patch (before the root)
        const double r2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
        if (r2 <= 1e-12) continue;
        const double r = std::sqrt(r2);
        const double cos_p = toward_p / r;
        if (cos_p <= 0) continue;
        const double w = k.area * cos_p / ((M_PI * r2 + k.area) * r);  // times d·axis
        const double light[3] = {w * k.r0, w * k.r1, w * k.r2};
        for (int axis = 0; axis < 3; ++axis) {
          const double c = d[axis];
          double* out = e[c > 0 ? 2 * axis : 2 * axis + 1];
          if (c > 0) {
            for (int ch = 0; ch < 3; ++ch) out[ch] += c * light[ch];
          } else {
            for (int ch = 0; ch < 3; ++ch) out[ch] -= c * light[ch];
          }
        }
      }
      for (int dir = 0; dir < 6; ++dir) {
        volume.values[dir * points + i] = Eigen::Vector3d(e[dir][0], e[dir][1], e[dir][2]).cast<float>();
      }
    }
  });
  return volume;
}

}  // namespace

namespace {

// The disk cache (bounce.h). This build of this file: its compile time and
// compiler. A volume is read only by the build that computed it, so a change
// to the arithmetic here (or to the inputs' meaning in the headers this file
// includes) never meets a volume computed the old way. Where builds are made
// reproducible (SOURCE_DATE_EPOCH fixes __DATE__ and __TIME__), the revision
// below is what tells them apart: bump it with any change to what
// BouncePatches or ComputeBounceVolume compute.
constexpr int kRevision = 1;
constexpr char kBuildStamp[] = __DATE__ " " __TIME__ " " __VERSION__;
constexpr char kMagic[8] = {'I', 'R', 'B', 'O', 'U', 'N', 'C', '1'};
// Files not read or written for this long are removed when another is written.
constexpr auto kUnusedFor = std::chrono::hours(24 * 30);
// The largest grid side a file may claim (the scene's own limit is 200,000
// volume points, docs/sensor.md).
constexpr int32_t kMaxSide = 1 << 16;

template <typename T>
void Put(std::string& out, const T& value) {
  out.append(reinterpret_cast<const char*>(&value), sizeof(T));
}

// Everything the volume is computed from, and this build.
std::string CacheKey(const TriangleMesh& mesh, const std::vector<IrLight>& lights, const BounceOptions& options) {
  std::string bytes(kBuildStamp, sizeof(kBuildStamp));
  Put(bytes, kRevision);
  Put(bytes, options.patch_m);
  Put(bytes, options.grid_m);
  Put(bytes, options.bounces);
  Put(bytes, lights.size());
  for (const IrLight& l : lights) {
    for (int k = 0; k < 3; ++k) Put(bytes, l.position[k]);
    for (int k = 0; k < 3; ++k) Put(bytes, l.direction[k]);
    Put(bytes, l.cone_deg);
    Put(bytes, l.power);
    Put(bytes, l.wavelength_nm);
  }
  Put(bytes, mesh.vertices.size());
  bytes.append(reinterpret_cast<const char*>(mesh.vertices.data()), mesh.vertices.size() * sizeof(MeshVertex));
  Put(bytes, mesh.indices.size());
  bytes.append(reinterpret_cast<const char*>(mesh.indices.data()), mesh.indices.size() * sizeof(uint32_t));
  return Sha256OfBytes(bytes);
}

std::string Serialise(const std::string& key, const IrradianceVolume& v) {
  std::string out(kMagic, sizeof(kMagic));
  out += key;
  for (int k = 0; k < 3; ++k) Put(out, v.origin[k]);
  Put(out, v.spacing);
  for (int k = 0; k < 3; ++k) Put(out, int32_t(v.dims[k]));
  Put(out, uint64_t(v.values.size()));
  for (const Eigen::Vector3f& e : v.values) {
    for (int c = 0; c < 3; ++c) Put(out, e[c]);
  }
  Put(out, Fnv1a64(out));
  return out;
}

// The volume in `bytes` when they are a whole, intact cache file for `key`.
std::optional<IrradianceVolume> Deserialise(const std::string& key, std::string_view bytes) {
  // The last 8 bytes: the FNV-1a hash of all before them (a file of the
  // right length with damaged contents, e.g. zeroed pages after a crash).
  uint64_t stored_hash = 0;
  if (bytes.size() < sizeof(stored_hash)) return std::nullopt;
  std::memcpy(&stored_hash, bytes.data() + bytes.size() - sizeof(stored_hash), sizeof(stored_hash));
  bytes.remove_suffix(sizeof(stored_hash));
  if (Fnv1a64(bytes) != stored_hash) return std::nullopt;
  size_t at = 0;
  auto take = [&](void* value, size_t n) {
    if (bytes.size() - at < n) return false;
    std::memcpy(value, bytes.data() + at, n);
    at += n;
    return true;
  };
  char magic[sizeof(kMagic)];
  std::string stored(key.size(), '\0');
  if (!take(magic, sizeof(magic)) || std::memcmp(magic, kMagic, sizeof(kMagic)) != 0) return std::nullopt;
  if (!take(stored.data(), stored.size()) || stored != key) return std::nullopt;
  IrradianceVolume v;
  int32_t dims[3];
  uint64_t count = 0;
  if (!take(v.origin.data(), 3 * sizeof(double)) || !take(&v.spacing, sizeof(double)) || !take(dims, sizeof(dims)) ||
      !take(&count, sizeof(count))) {
    return std::nullopt;
  }
  // No volume (every side 0), or sides of 2 or more that Irradiance can
  // interpolate in, on a finite grid.
  const bool none = dims[0] == 0 && dims[1] == 0 && dims[2] == 0;
  for (int k = 0; k < 3; ++k) {
    if (!none && (dims[k] < 2 || dims[k] > kMaxSide)) return std::nullopt;
    if (!std::isfinite(v.origin[k])) return std::nullopt;
    v.dims[k] = dims[k];
  }
  if (!(std::isfinite(v.spacing) && v.spacing > 0)) return std::nullopt;
  if (count != 6 * uint64_t(dims[0]) * uint64_t(dims[1]) * uint64_t(dims[2])) return std::nullopt;
  if (bytes.size() - at != count * 3 * sizeof(float)) return std::nullopt;
  v.values.resize(count);
  for (Eigen::Vector3f& e : v.values) take(e.data(), 3 * sizeof(float));
  return v;
}

// The cache file of `key` (empty without a cache folder).
std::filesystem::path CacheFile(const std::string& key) {
  const std::filesystem::path root = UserCacheDir();
  return root.empty() ? root : root / "bounce" / (key + ".bin");
}

std::optional<IrradianceVolume> ReadCached(const std::filesystem::path& file, const std::string& key) {
  const std::string bytes = ReadFileBytes(file);
  if (bytes.empty()) return std::nullopt;  // none yet (or unreadable): a miss
  std::optional<IrradianceVolume> v = Deserialise(key, bytes);
  if (!v) Log().warn("bounce light: ignoring the damaged cache file {} (computing it again)", file.string());
  return v;
}

// Writes the volume's file (a file that cannot be written is only a cache
// miss next time) and removes files of the folder not read or written for a
// month (killed writers' temporaries after a day).
void WriteCached(const std::filesystem::path& file, const std::string& key, const IrradianceVolume& volume) {
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::create_directories(file.parent_path(), ec);
  try {
    AtomicWriteFile(file, Serialise(key, volume));
  } catch (const std::exception& e) {
    Log().debug("bounce light: not cached: {}", e.what());
    return;
  }
  const auto now = fs::file_time_type::clock::now();
  for (fs::directory_iterator it(file.parent_path(), ec), end; !ec && it != end; it.increment(ec)) {
    // Volumes, and the temporaries of writers that were killed.
    const fs::path p = it->path();
    const std::string name = p.filename().string();
    const bool temporary = name.starts_with(".") && name.find(".bin.tmp-") != std::string::npos;
    if ((p.extension() != ".bin" && !temporary) || p == file) continue;
    std::error_code time_ec;
    const auto written = fs::last_write_time(p, time_ec);
    if (!time_ec && now - written > (temporary ? std::chrono::hours(24) : kUnusedFor)) fs::remove(p, time_ec);
  }
}

}  // namespace

std::filesystem::path BounceCacheFile(const TriangleMesh& mesh,
                                      const std::vector<IrLight>& lights,
                                      const BounceOptions& options) {
  return UserCacheDir().empty() ? std::filesystem::path() : CacheFile(CacheKey(mesh, lights, options));
}

IrradianceVolume ComputeBounce(const TriangleMesh& mesh,
                               const std::vector<IrLight>& lights,
                               const BounceOptions& options) {
  if (std::optional<IrradianceVolume> kept = LastBounceVolume().Find(mesh, lights, options)) return *std::move(kept);
  const std::string key = UserCacheDir().empty() ? std::string() : CacheKey(mesh, lights, options);
  const std::filesystem::path file = key.empty() ? std::filesystem::path() : CacheFile(key);
  if (!file.empty()) {
    if (std::optional<IrradianceVolume> cached = ReadCached(file, key)) {
      Log().debug("bounce light: read from {}", file.string());
      // Read counts as used: the month's pruning spares it.
      std::error_code ec;
      std::filesystem::last_write_time(file, std::filesystem::file_time_type::clock::now(), ec);
      LastBounceVolume().Keep(mesh, lights, options, *cached);
      return *std::move(cached);
    }
  }
  IrradianceVolume volume = ComputeBounceVolume(mesh, lights, options);
  LastBounceVolume().Keep(mesh, lights, options, volume);
  if (!file.empty()) WriteCached(file, key, volume);
  return volume;
}


Eigen::Vector3f IrradianceVolume::Irradiance(const Eigen::Vector3d& p, const Eigen::Vector3d& normal) const {
  if (empty()) return Eigen::Vector3f::Zero();
  const size_t points = size_t(dims.x()) * dims.y() * dims.z();
  const Eigen::Vector3d g = (p - origin) / spacing;
  int i0[3];
  double f[3];
  for (int k = 0; k < 3; ++k) {
    const double c = std::clamp(g[k], 0.0, double(dims[k] - 1));
    i0[k] = std::min(static_cast<int>(std::floor(c)), dims[k] - 2);
    f[k] = c - i0[k];
  }
  const Eigen::Vector3d n = normal.normalized();
  Eigen::Vector3f total = Eigen::Vector3f::Zero();
  for (int axis = 0; axis < 3; ++axis) {
    const int dir = 2 * axis + (n[axis] >= 0 ? 0 : 1);
    Eigen::Vector3f e = Eigen::Vector3f::Zero();
    for (int corner = 0; corner < 8; ++corner) {
      const int cx = corner & 1, cy = (corner >> 1) & 1, cz = (corner >> 2) & 1;
      const double w = (cx ? f[0] : 1 - f[0]) * (cy ? f[1] : 1 - f[1]) * (cz ? f[2] : 1 - f[2]);
      const size_t index = (size_t(i0[2] + cz) * dims.y() + (i0[1] + cy)) * dims.x() + (i0[0] + cx);
      e += static_cast<float>(w) * values[dir * points + index];
    }
    total += static_cast<float>(n[axis] * n[axis]) * e;
  }
  return total;
}

}  // namespace irbench
