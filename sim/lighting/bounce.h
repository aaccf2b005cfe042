#pragma once
// Diffuse bounce light (docs/sensor.md "Bounce light"): the illuminators'
// light reflected off the static scene — above all the screens, which the
// illuminators face, and the floor — and the near IR the screens' projected
// content emits, gathered into an irradiance volume the renderer reads at
// every vertex (static meshes are cut to short edges for it).
//
// The static mesh is cut into patches of about `patch_m`. Each patch's
// radiosity B = reflectance × irradiance (the renderer's radiance units:
// radiance 1 = white under irradiance 1) is first its direct light from the
// illuminators (cone, cosine, 1/d², the renderer's own formula; no static
// occlusion) plus its content emission, then `bounces` - 1 gathers of the
// other patches' light. The volume holds, on a grid over the mesh's bounds, the
// irradiance from every patch onto the six axis normals (an "ambient cube"); a
// normal n gets Σ n_i² E(±axis_i). A patch of area A and radiosity B adds
// B A cosθ_p cosθ_x / (π r² + A) (exact on the axis of a disc of area A).
// Three channels, after how the sensor weighs them and how they flicker:
// 0 the illuminators' light at 850 nm, 1 at 940 nm, 2 the screens' content.
// A patch takes and gives light on the side its normal faces (rooms inwards,
// boxes outwards, screens towards the audience, quads along u x v).
// What is not modelled: occlusion between static surfaces (the patches see
// each other through boxes) and the person's shadow in the bounce light.

#include <Eigen/Core>
#include <filesystem>
#include <vector>

#include "sim/scene/mesh.h"
#include "sim/scene/scene.h"

namespace irbench {

enum BounceChannel : int { kIlluminator850 = 0, kIlluminator940 = 1, kScreenContent = 2 };

struct BounceOptions {
  double patch_m = 0.5;  // longest patch edge
  double grid_m = 0.5;   // volume spacing
  int bounces = 2;       // 1: only light reflected once
};

struct IrradianceVolume {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();  // grid point (0, 0, 0)
  double spacing = 1.0;
  Eigen::Vector3i dims = Eigen::Vector3i::Zero();  // 0: no volume
  // values[((d * dims.z() + z) * dims.y() + y) * dims.x() + x] for direction
  // d = +x, -x, +y, -y, +z, -z: irradiance onto a surface facing d, 3 channels.
  std::vector<Eigen::Vector3f> values;

  bool empty() const { return values.empty(); }
  // Trilinear in space, ambient-cube in the normal (as the shader does).
  Eigen::Vector3f Irradiance(const Eigen::Vector3d& p, const Eigen::Vector3d& normal) const;
};

// A patch of the static scene (exposed for tests).
struct BouncePatch {
  Eigen::Vector3d center, normal;
  double area = 0;
  NirReflectance reflectance;
  float content = 0;            // content emission
  Eigen::Vector3f radiosity = Eigen::Vector3f::Zero();  // per channel
};

// Patches of `mesh` (emissive surfaces excluded) with their radiosity.
std::vector<BouncePatch> BouncePatches(const TriangleMesh& mesh,
                                       const std::vector<IrLight>& lights,
                                       const BounceOptions& options);

// The bounce light's irradiance volume. The last one computed is kept (a
// suite or sweep renders one scene many times in one process): the same
// inputs, bit for bit, return it again. Across processes each volume is kept
// on disk in UserCacheDir()/bounce/ (common/paths.h; IRBENCH_CACHE_DIR=off: no
// disk cache): a file per scene mesh, lights, options and build of the
// bounce code (BounceCacheFile), read back only for exactly those, so the
// volume read is the one computing it gives, bit for bit (on this machine:
// std::cos is the C library's, which may pick another implementation on
// another processor, so a cache folder shared by different machines may give
// a volume that differs in the last bits). A file that is not whole or fails
// its hash is ignored (a warning) and written again.
IrradianceVolume ComputeBounce(const TriangleMesh& mesh,
                               const std::vector<IrLight>& lights,
                               const BounceOptions& options = {});

// The disk cache's file for these inputs (empty without a cache folder):
// "IRBOUNC1", the 64 hex digits of the inputs' SHA-256 (also its name), the
// volume's origin (3 doubles), spacing (double), dims (3 int32), the number
// of values (uint64), the values (3 floats each) and the 64-bit FNV-1a hash
// of everything before it (Fnv1a64, common/atomic_file.h), in this
// machine's byte order.
std::filesystem::path BounceCacheFile(const TriangleMesh& mesh,
                                      const std::vector<IrLight>& lights,
                                      const BounceOptions& options = {});

}  // namespace irbench
