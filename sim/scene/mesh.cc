#include "sim/scene/mesh.h"

#include <cmath>

namespace irbench {

void TriangleMesh::Append(const TriangleMesh& other) {
  const uint32_t base = static_cast<uint32_t>(vertices.size());
  vertices.insert(vertices.end(), other.vertices.begin(), other.vertices.end());
  for (uint32_t i : other.indices) indices.push_back(base + i);
}

void AppendQuad(TriangleMesh& mesh,
                const Eigen::Vector3d& origin,
                const Eigen::Vector3d& u,
                const Eigen::Vector3d& v,
                const Material& material,
                int n_u,
                int n_v) {
  const Eigen::Vector3f normal = u.cross(v).normalized().cast<float>();
  const uint32_t base = static_cast<uint32_t>(mesh.vertices.size());
  for (int j = 0; j <= n_v; ++j) {
    for (int i = 0; i <= n_u; ++i) {
      MeshVertex vertex;
      vertex.position = (origin + u * (double(i) / n_u) + v * (double(j) / n_v)).cast<float>();
      vertex.normal = normal;
      material.Apply(vertex);
      mesh.vertices.push_back(vertex);
    }
  }
  for (int j = 0; j < n_v; ++j) {
    for (int i = 0; i < n_u; ++i) {
      const uint32_t a = base + j * (n_u + 1) + i;
      const uint32_t b = a + 1, c = a + (n_u + 1), d = c + 1;
      mesh.indices.insert(mesh.indices.end(), {a, b, d, a, d, c});
    }
  }
}

void AppendBox(TriangleMesh& mesh,
               const Eigen::Vector3d& min,
               const Eigen::Vector3d& max,
               const Material& material,
               bool inward) {
  AppendRoom(mesh, min, max, material, material, material);
  if (!inward) {
    // Flip the six faces just appended to face outwards.
    const size_t first_vertex = mesh.vertices.size() - 6 * 4;
    for (size_t i = first_vertex; i < mesh.vertices.size(); ++i) {
      mesh.vertices[i].normal = -mesh.vertices[i].normal;
    }
  }
}

void AppendRoom(TriangleMesh& mesh,
                const Eigen::Vector3d& min,
                const Eigen::Vector3d& max,
                const Material& floor,
                const Material& ceiling,
                const Material& walls) {
  const Eigen::Vector3d size = max - min;
  const Eigen::Vector3d ex(size.x(), 0, 0), ey(0, size.y(), 0), ez(0, 0, size.z());
  // Each face's u x v points into the box.
  AppendQuad(mesh, min, ex, ey, floor);                                   // floor, normal +z
  AppendQuad(mesh, min + ez, ey, ex, ceiling);                            // ceiling, -z
  AppendQuad(mesh, min, ez, ex, walls);                                   // y = min, +y
  AppendQuad(mesh, min + ey, ex, ez, walls);                              // y = max, -y
  AppendQuad(mesh, min, ey, ez, walls);                                   // x = min, +x
  AppendQuad(mesh, min + ex, ez, ey, walls);                              // x = max, -x
}

void AppendSphere(TriangleMesh& mesh,
                  const Eigen::Vector3d& center,
                  double radius,
                  const Material& material,
                  int n_lon,
                  int n_lat) {
  const uint32_t base = static_cast<uint32_t>(mesh.vertices.size());
  for (int j = 0; j <= n_lat; ++j) {
    const double theta = M_PI * j / n_lat;
    for (int i = 0; i <= n_lon; ++i) {
      const double phi = 2 * M_PI * i / n_lon;
      const Eigen::Vector3d n(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi),
                              std::cos(theta));
      MeshVertex vertex;
      vertex.position = (center + radius * n).cast<float>();
      vertex.normal = n.cast<float>();
      material.Apply(vertex);
      mesh.vertices.push_back(vertex);
    }
  }
  for (int j = 0; j < n_lat; ++j) {
    for (int i = 0; i < n_lon; ++i) {
      const uint32_t a = base + j * (n_lon + 1) + i;
      const uint32_t b = a + 1, c = a + (n_lon + 1), d = c + 1;
      mesh.indices.insert(mesh.indices.end(), {a, c, d, a, d, b});
    }
  }
}

void AppendCheckerboard(TriangleMesh& mesh,
                        const Eigen::Isometry3d& world_from_board,
                        int inner_cols,
                        int inner_rows,
                        double square_m,
                        double margin_squares) {
  const Material black{0.05f, 1.0f};
  const Material white{0.95f, 1.0f};
  const Eigen::Matrix3d rot = world_from_board.linear();
  auto to_world = [&](double x, double y) {
    return world_from_board * Eigen::Vector3d(x, y, 0);
  };
  // The board's front faces +z of the board frame; quads are built with
  // u x v = +z (x then y), so the normal is rot * z.
  const Eigen::Vector3d ux = rot * Eigen::Vector3d(square_m, 0, 0);
  const Eigen::Vector3d uy = rot * Eigen::Vector3d(0, square_m, 0);
  // Squares span [-1, inner_cols] x [-1, inner_rows] in square units.
  for (int r = -1; r < inner_rows; ++r) {
    for (int c = -1; c < inner_cols; ++c) {
      const bool is_black = ((r + c) % 2 + 2) % 2 == 0;
      AppendQuad(mesh, to_world(c * square_m, r * square_m), ux, uy, is_black ? black : white);
    }
  }
  const double m = margin_squares * square_m;
  const double x0 = -square_m, x1 = inner_cols * square_m;
  const double y0 = -square_m, y1 = inner_rows * square_m;
  const Eigen::Vector3d ex = rot.col(0), ey = rot.col(1);
  // Margin: bottom and top strips across the full width, left and right strips.
  AppendQuad(mesh, to_world(x0 - m, y0 - m), ex * (x1 - x0 + 2 * m), ey * m, white);
  AppendQuad(mesh, to_world(x0 - m, y1), ex * (x1 - x0 + 2 * m), ey * m, white);
  AppendQuad(mesh, to_world(x0 - m, y0), ex * m, ey * (y1 - y0), white);
  AppendQuad(mesh, to_world(x1, y0), ex * m, ey * (y1 - y0), white);
}

}  // namespace irbench
