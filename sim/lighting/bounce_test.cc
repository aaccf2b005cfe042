// The bounce light against analytic view factors: a uniformly emitting square
// seen from a point on its axis, a patch's direct light, one gather between
// two facing plates, and the wavelength bands.

#include "sim/lighting/bounce.h"

#include <gtest/gtest.h>

#include <stdlib.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <optional>
#include <string>

#include "common/atomic_file.h"
#include "tests/test_util.h"

namespace irbench {
namespace {

// View factor from a differential area parallel to a rectangle, on the normal
// through one of its corners, at distance h (X = a / h, Y = b / h).
double CornerViewFactor(double a, double b, double h) {
  const double x = a / h, y = b / h;
  return (x / std::sqrt(1 + x * x) * std::atan(y / std::sqrt(1 + x * x)) +
          y / std::sqrt(1 + y * y) * std::atan(x / std::sqrt(1 + y * y))) /
         (2 * M_PI);
}

// Irradiance at height h above the centre of a square of side s whose
// radiosity is B (renderer units: E = B F).
double SquareAxisIrradiance(double radiosity, double side, double h) {
  return radiosity * 4 * CornerViewFactor(side / 2, side / 2, h);
}

Material ContentEmitter(float content) {
  Material m;
  m.albedo = 0.0f;
  m.content = content;
  return m;
}

TEST(BounceTest, EmittingSquareMatchesItsViewFactor) {
  TriangleMesh mesh;
  // A 2 m square at z = 0 facing up, emitting content radiance 0.8.
  AppendQuad(mesh, {-1, -1, 0}, {2, 0, 0}, {0, 2, 0}, ContentEmitter(0.8f));
  // A black ceiling only to extend the volume's bounds.
  AppendQuad(mesh, {-1, -1, 3}, {0, 2, 0}, {2, 0, 0}, Material{0.0f, 0.0f});
  BounceOptions options;
  options.patch_m = 0.05;
  options.grid_m = 0.25;
  const IrradianceVolume volume = ComputeBounce(mesh, {}, options);
  ASSERT_FALSE(volume.empty());
  for (double h : {0.5, 1.0, 2.0}) {
    const double expected = SquareAxisIrradiance(0.8, 2.0, h);
    const Eigen::Vector3f e = volume.Irradiance({0, 0, h}, {0, 0, -1});
    EXPECT_NEAR(e[kScreenContent], expected, 0.02 * expected) << "h " << h;
    // Facing away from the square, a point gets nothing from it.
    EXPECT_EQ(volume.Irradiance({0, 0, h}, {0, 0, 1})[kScreenContent], 0.0f);
    std::printf("h %.1f m: irradiance %.5f, view factor predicts %.5f\n", h, e[kScreenContent], expected);
  }
}

TEST(BounceTest, PatchesCarryTheRenderersDirectLightPerWavelength) {
  TriangleMesh mesh;
  Material floor;
  floor.albedo = 0.6f;
  floor.albedo_940 = 0.3f;
  AppendQuad(mesh, {-2, -2, 0}, {4, 0, 0}, {0, 4, 0}, floor);
  IrLight light;
  light.position = {0, 0, 2};
  light.direction = {0, 0, -1};
  light.cone_deg = 170;
  light.power = 4;
  light.wavelength_nm = 940;
  BounceOptions options;
  options.patch_m = 0.2;
  options.bounces = 1;
  const std::vector<BouncePatch> patches = BouncePatches(mesh, {light}, options);
  ASSERT_GT(patches.size(), 100u);
  double area = 0;
  for (const BouncePatch& p : patches) {
    area += p.area;
    const Eigen::Vector3d to_light = light.position - p.center;
    const double e = light.power * to_light.normalized().z() / to_light.squaredNorm();
    EXPECT_NEAR(p.radiosity[kIlluminator940], 0.3 * e, 1e-5 * e);
    EXPECT_EQ(p.radiosity[kIlluminator850], 0.0f);
    EXPECT_EQ(p.normal.z(), 1.0);
  }
  EXPECT_NEAR(area, 16.0, 1e-9);
}

TEST(BounceTest, SecondBounceGathersFromTheFacingPlate) {
  // Plate A (z = 0, up) emits; plate B (z = 1, down) reflects half of what
  // reaches it; B's centre patch then has radiosity 0.5 E_A(centre).
  TriangleMesh mesh;
  AppendQuad(mesh, {-1.5, -1.5, 0}, {3, 0, 0}, {0, 3, 0}, ContentEmitter(1.0f));
  AppendQuad(mesh, {-1.5, -1.5, 1}, {0, 3, 0}, {3, 0, 0}, Material{0.5f, 0.0f});
  BounceOptions options;
  options.patch_m = 0.1;
  options.bounces = 2;
  const std::vector<BouncePatch> patches = BouncePatches(mesh, {}, options);
  const BouncePatch* centre = nullptr;
  for (const BouncePatch& p : patches) {
    if (p.center.z() > 0.5 && (!centre || p.center.head<2>().norm() < centre->center.head<2>().norm())) centre = &p;
  }
  ASSERT_NE(centre, nullptr);
  ASSERT_LT(centre->center.head<2>().norm(), 0.05);
  const double expected = 0.5 * SquareAxisIrradiance(1.0, 3.0, 1.0);
  EXPECT_NEAR(centre->radiosity[kScreenContent], expected, 0.02 * expected);
  options.bounces = 1;
  for (const BouncePatch& p : BouncePatches(mesh, {}, options)) {
    if (p.center.z() > 0.5) EXPECT_EQ(p.radiosity[kScreenContent], 0.0f);
  }
}

// The volume kept from the last call is only returned for the same inputs:
// a light twice as strong doubles the volume, the first light again gives the
// first volume exactly, and a changed reflectance changes it.
TEST(BounceTest, TheKeptVolumeFollowsItsInputs) {
  TriangleMesh mesh;
  AppendQuad(mesh, {-1.5, -1.5, 0}, {3, 0, 0}, {0, 3, 0}, Material{0.5f, 0.0f});
  AppendQuad(mesh, {-1.5, -1.5, 2}, {0, 3, 0}, {3, 0, 0}, Material{0.5f, 0.0f});
  IrLight light;
  light.position = {0, 0, 1.5};
  light.direction = -Eigen::Vector3d::UnitZ();
  light.cone_deg = 120;
  const IrradianceVolume first = ComputeBounce(mesh, {light});
  ASSERT_FALSE(first.empty());
  IrLight brighter = light;
  brighter.power = 2 * light.power;
  const IrradianceVolume doubled = ComputeBounce(mesh, {brighter});
  ASSERT_EQ(doubled.values.size(), first.values.size());
  double largest = 0;
  for (size_t i = 0; i < first.values.size(); ++i) {
    EXPECT_LT((doubled.values[i] - 2 * first.values[i]).norm(), 1e-5 * (1 + first.values[i].norm())) << i;
    largest = std::max<double>(largest, first.values[i].norm());
  }
  EXPECT_GT(largest, 0);
  const IrradianceVolume again = ComputeBounce(mesh, {light});
  EXPECT_EQ(again.values, first.values);
  TriangleMesh darker = mesh;
  for (MeshVertex& v : darker.vertices) v.albedo = 0.25f;
  const IrradianceVolume dim = ComputeBounce(darker, {light});
  EXPECT_NE(dim.values, first.values);
}

// Sets IRBENCH_CACHE_DIR for one test and restores it after.
class CacheDirForTest {
 public:
  explicit CacheDirForTest(const std::string& value) {
    if (const char* old = std::getenv("IRBENCH_CACHE_DIR")) old_ = old;
    ::setenv("IRBENCH_CACHE_DIR", value.c_str(), 1);
  }
  ~CacheDirForTest() {
    if (old_) ::setenv("IRBENCH_CACHE_DIR", old_->c_str(), 1); else ::unsetenv("IRBENCH_CACHE_DIR");
  }

 private:
  std::optional<std::string> old_;
};

void ExpectSameVolume(const IrradianceVolume& a, const IrradianceVolume& b) {
  EXPECT_EQ(a.origin, b.origin);
  EXPECT_EQ(a.spacing, b.spacing);
  EXPECT_EQ(a.dims, b.dims);
  EXPECT_EQ(a.values, b.values);
}

// The disk cache (another process's volume) gives exactly what computing
// gives, only for the same inputs, is really read (a changed value in the
// file, its hash made good, comes back), and a file cut short, damaged or
// holding another scene's volume is computed and written again.
TEST(BounceTest, TheDiskCacheGivesTheComputedVolumeOnlyForItsInputs) {
  namespace fs = std::filesystem;
  const fs::path dir = testing::FreshTempDir("bounce_cache");
  struct RemoveAfter {
    fs::path dir;
    ~RemoveAfter() { fs::remove_all(dir); }
  } remove_after{dir};
  TriangleMesh mesh, other;
  AppendQuad(mesh, {-1.5, -1.5, 0}, {3, 0, 0}, {0, 3, 0}, Material{0.5f, 0.0f});
  AppendQuad(mesh, {-1.5, -1.5, 2}, {0, 3, 0}, {3, 0, 0}, Material{0.5f, 0.0f});
  AppendQuad(other, {-1, -1, 0}, {2, 0, 0}, {0, 2, 0}, Material{0.5f, 0.0f});
  IrLight light;
  light.position = {0, 0, 1.5};
  light.cone_deg = 120;
  {
    // No cache: no file, nothing written.
    CacheDirForTest no_cache("off");
    EXPECT_TRUE(BounceCacheFile(mesh, {light}).empty());
    ComputeBounce(other, {light});
    ComputeBounce(mesh, {light});
    EXPECT_TRUE(fs::is_empty(dir));
  }
  CacheDirForTest cache(dir.string());
  const fs::path file = BounceCacheFile(mesh, {light});
  ASSERT_EQ(file.parent_path(), dir / "bounce");
  IrLight brighter = light;
  brighter.power = 2;
  EXPECT_NE(BounceCacheFile(mesh, {brighter}), file);
  EXPECT_NE(BounceCacheFile(other, {light}), file);
  // Computed, and written.
  ComputeBounce(other, {light});  // not the last volume kept in memory
  const IrradianceVolume computed = ComputeBounce(mesh, {light});
  ASSERT_FALSE(computed.empty());
  ASSERT_TRUE(fs::is_regular_file(file));
  // The file as a fresh process reads it (the other scene's volume is the one
  // kept in memory): the same volume, bit for bit.
  ComputeBounce(other, {light});
  ExpectSameVolume(ComputeBounce(mesh, {light}), computed);
  // Read, not computed: the last value changed in the file (and the hash
  // after it recomputed) comes back.
  const std::string whole = testing::ReadText(file);
  const size_t header = 8 + 64 + 4 * sizeof(double) + 3 * 4 + 8, hash = 8;
  ASSERT_EQ(whole.size(), header + computed.values.size() * 3 * sizeof(float) + hash);
  std::string changed = whole.substr(0, whole.size() - hash);
  const float marker = 12345.5f;
  std::memcpy(changed.data() + changed.size() - sizeof(float), &marker, sizeof(float));
  const uint64_t changed_hash = Fnv1a64(changed);
  changed.append(reinterpret_cast<const char*>(&changed_hash), hash);
  testing::WriteText(file, changed);
  ComputeBounce(other, {light});
  EXPECT_EQ(ComputeBounce(mesh, {light}).values.back()[2], marker);
  // Damaged where the hash does not match, or cut short: ignored, computed
  // again and written whole.
  std::string damaged = whole;
  damaged[header + 5] ^= 0x40;
  for (const std::string& bad : {damaged, whole.substr(0, whole.size() - 1)}) {
    testing::WriteText(file, bad);
    ComputeBounce(other, {light});
    ExpectSameVolume(ComputeBounce(mesh, {light}), computed);
    EXPECT_EQ(testing::ReadText(file), whole);
  }
  // Another scene's file under this one's name: its key differs inside.
  const fs::path other_file = BounceCacheFile(other, {light});
  ASSERT_TRUE(fs::is_regular_file(other_file));
  fs::copy_file(other_file, file, fs::copy_options::overwrite_existing);
  ComputeBounce(other, {brighter});
  ExpectSameVolume(ComputeBounce(mesh, {light}), computed);
  EXPECT_EQ(testing::ReadText(file), whole);
  // Brighter light: its own file, its own volume.
  ComputeBounce(mesh, {brighter});
  EXPECT_TRUE(fs::is_regular_file(BounceCacheFile(mesh, {brighter})));
}

}  // namespace
}  // namespace irbench
