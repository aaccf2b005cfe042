#include "sim/scene/screen_mesh.h"

#include <cmath>

namespace irbench {
namespace {
constexpr double kDegToRad = M_PI / 180.0;
}

void AppendScreenGeometry(const ScreenSurface& screen,
                          const Material& material,
                          TriangleMesh& mesh) {
  if (screen.kind == ScreenSurface::Kind::kPlane) {
    // Front faces right x up; AppendQuad's normal is u x v.
    AppendQuad(mesh, screen.origin, screen.right * screen.width, screen.up * screen.height,
               material, 4, 2);
    return;
  }
  const int segments = 64;
  const uint32_t base = static_cast<uint32_t>(mesh.vertices.size());
  for (int i = 0; i <= segments; ++i) {
    const double angle =
        (screen.angle_left_deg + (screen.angle_right_deg - screen.angle_left_deg) * i / segments) *
        kDegToRad;
    const Eigen::Vector3d radial(std::cos(angle), std::sin(angle), 0);
    for (double z : {screen.z0, screen.z1}) {
      MeshVertex v;
      v.position =
          (Eigen::Vector3d(screen.center_xy.x(), screen.center_xy.y(), z) + screen.radius * radial)
              .cast<float>();
      v.normal = (-radial).cast<float>();  // faces the centre
      material.Apply(v);
      mesh.vertices.push_back(v);
    }
  }
  for (int i = 0; i < segments; ++i) {
    const uint32_t a = base + 2 * i, b = a + 1, c = a + 2, d = a + 3;
    mesh.indices.insert(mesh.indices.end(), {a, c, d, a, d, b});
  }
}

}  // namespace irbench
