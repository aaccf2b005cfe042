#pragma once
// Triangle meshes as the renderer consumes them, and builders for the simple
// shapes scenes are made of.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <vector>

namespace irbench {

// Near-IR diffuse reflectance at the two illuminator wavelengths.
struct NirReflectance {
  float at_850 = 0.5f;
  float at_940 = 0.5f;
  static NirReflectance Grey(float r) { return {r, r}; }
  bool operator==(const NirReflectance&) const = default;
};

struct MeshVertex {
  Eigen::Vector3f position = Eigen::Vector3f::Zero();  // world, metres
  Eigen::Vector3f normal = Eigen::Vector3f::UnitZ();
  float albedo = 0.5f;    // near-IR reflectance at 850 nm, in [0, 1]
  float emissive = 0.0f;  // 1: shows `albedo` directly, unlit (calibration boards)
  float albedo_940 = -1.0f;  // reflectance at 940 nm; negative: the same as `albedo`
  // Radiance the surface emits with the screens' projected content (relative,
  // like the renderer's radiance); it follows the content's flicker.
  float content = 0.0f;

  void SetReflectance(const NirReflectance& r) {
    albedo = r.at_850;
    albedo_940 = r.at_940;
  }
  NirReflectance Reflectance() const { return {albedo, albedo_940 < 0 ? albedo : albedo_940}; }
};
static_assert(sizeof(MeshVertex) == 10 * sizeof(float), "tightly packed for the GPU");

struct TriangleMesh {
  std::vector<MeshVertex> vertices;
  std::vector<uint32_t> indices;  // three per triangle

  size_t TriangleCount() const { return indices.size() / 3; }
  void Append(const TriangleMesh& other);
};

struct Material {
  float albedo = 0.5f;        // reflectance at 850 nm
  float emissive = 0.0f;      // 1: unlit, shows `albedo`
  float albedo_940 = -1.0f;   // negative: the same as `albedo`
  float content = 0.0f;       // radiance from projected content (screens)

  static Material Of(const NirReflectance& r) { return {r.at_850, 0.0f, r.at_940, 0.0f}; }
  void Apply(MeshVertex& v) const {
    v.albedo = albedo;
    v.emissive = emissive;
    v.albedo_940 = albedo_940;
    v.content = content;
  }
};

// A parallelogram `origin + a*u + b*v`, a,b in [0,1], subdivided n_u x n_v;
// its normal is u x v normalised.
void AppendQuad(TriangleMesh& mesh,
                const Eigen::Vector3d& origin,
                const Eigen::Vector3d& u,
                const Eigen::Vector3d& v,
                const Material& material,
                int n_u = 1,
                int n_v = 1);

// An axis-aligned box; `inward` makes the faces look inside (a room).
void AppendBox(TriangleMesh& mesh,
               const Eigen::Vector3d& min,
               const Eigen::Vector3d& max,
               const Material& material,
               bool inward);

// A room: an inward box with separate floor, ceiling and wall materials.
void AppendRoom(TriangleMesh& mesh,
                const Eigen::Vector3d& min,
                const Eigen::Vector3d& max,
                const Material& floor,
                const Material& ceiling,
                const Material& walls);

// A UV sphere (for tests: a shape with an analytic projection).
void AppendSphere(TriangleMesh& mesh,
                  const Eigen::Vector3d& center,
                  double radius,
                  const Material& material,
                  int n_lon = 96,
                  int n_lat = 48);

// A planar checkerboard with (inner_cols x inner_rows) inner corners and a white
// margin of `margin_squares`. Board frame: origin at the first inner corner, x
// along columns, y along rows, z the normal the board faces (towards the camera).
// Emissive black (0.05) and white (0.95).
void AppendCheckerboard(TriangleMesh& mesh,
                        const Eigen::Isometry3d& world_from_board,
                        int inner_cols,
                        int inner_rows,
                        double square_m,
                        double margin_squares = 1.0);

}  // namespace irbench
