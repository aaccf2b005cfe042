#include "tracker/hull/ply.h"

#include <algorithm>
#include <bit>
#include <cstring>
#include <sstream>
#include <string>
#include <unordered_map>

#include "common/atomic_file.h"

namespace irbench {
namespace {

void AppendRaw(std::string& out, const void* data, size_t n) {
  out.append(static_cast<const char*>(data), n);
}

static_assert(std::endian::native == std::endian::little ||
              std::endian::native == std::endian::big);

template <typename T>
void AppendLittle(std::string& out, T value) {
  char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  if constexpr (std::endian::native == std::endian::big) std::reverse(bytes, bytes + sizeof(T));
  AppendRaw(out, bytes, sizeof(T));
}

std::string Header(PlyFormat format, size_t vertices, size_t faces, bool with_faces) {
  std::ostringstream h;
  h << "ply\nformat " << (format == PlyFormat::kAscii ? "ascii" : "binary_little_endian")
    << " 1.0\n"
    << "comment irbench hull, world metres, z up\n"
    << "element vertex " << vertices << "\nproperty float x\nproperty float y\nproperty float z\n";
  if (with_faces) h << "element face " << faces << "\nproperty list uchar uint vertex_indices\n";
  h << "end_header\n";
  return h.str();
}

std::string Encode(const std::vector<Eigen::Vector3d>& vertices,
                   const std::vector<std::array<uint32_t, 3>>* triangles,
                   PlyFormat format) {
  std::string out =
      Header(format, vertices.size(), triangles ? triangles->size() : 0, triangles != nullptr);
  if (format == PlyFormat::kAscii) {
    std::ostringstream body;
    body.precision(7);
    for (const auto& v : vertices)
      body << float(v.x()) << ' ' << float(v.y()) << ' ' << float(v.z()) << '\n';
    if (triangles) {
      for (const auto& t : *triangles) body << "3 " << t[0] << ' ' << t[1] << ' ' << t[2] << '\n';
    }
    out += body.str();
  } else {
    out.reserve(out.size() + vertices.size() * 12 + (triangles ? triangles->size() * 13 : 0));
    for (const auto& v : vertices) {
      for (int k = 0; k < 3; ++k) AppendLittle(out, static_cast<float>(v[k]));
    }
    if (triangles) {
      for (const auto& t : *triangles) {
        AppendLittle(out, uint8_t{3});
        for (int k = 0; k < 3; ++k) AppendLittle(out, t[k]);
      }
    }
  }
  return out;
}

}  // namespace

HullMesh VoxelSurfaceMesh(const VoxelHull& hull) {
  HullMesh mesh;
  std::unordered_map<uint64_t, uint32_t> lattice_vertex;
  auto vertex = [&](int x, int y, int z) {
    const uint64_t key = (uint64_t(z) * (hull.ny + 1) + y) * (hull.nx + 1) + x;
    auto [it, fresh] = lattice_vertex.try_emplace(key, static_cast<uint32_t>(mesh.vertices.size()));
    if (fresh)
      mesh.vertices.push_back(hull.origin_m + hull.voxel_size_m * Eigen::Vector3d(x, y, z));
    return it->second;
  };
  auto occupied = [&](int x, int y, int z) {
    return x >= 0 && y >= 0 && z >= 0 && x < hull.nx && y < hull.ny && z < hull.nz &&
           hull.Occupied(x, y, z);
  };
  // For each axis and side, the face's 4 corners (offsets) counter-clockwise
  // seen from outside.
  struct Face {
    int dx, dy, dz;
    int c[4][3];
  };
  static const Face kFaces[6] = {
      {-1, 0, 0, {{0, 0, 0}, {0, 0, 1}, {0, 1, 1}, {0, 1, 0}}},
      {1, 0, 0, {{1, 0, 0}, {1, 1, 0}, {1, 1, 1}, {1, 0, 1}}},
      {0, -1, 0, {{0, 0, 0}, {1, 0, 0}, {1, 0, 1}, {0, 0, 1}}},
      {0, 1, 0, {{0, 1, 0}, {0, 1, 1}, {1, 1, 1}, {1, 1, 0}}},
      {0, 0, -1, {{0, 0, 0}, {0, 1, 0}, {1, 1, 0}, {1, 0, 0}}},
      {0, 0, 1, {{0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}}},
  };
  for (int z = 0; z < hull.nz; ++z) {
    for (int y = 0; y < hull.ny; ++y) {
      for (int x = 0; x < hull.nx; ++x) {
        if (!hull.Occupied(x, y, z)) continue;
        for (const Face& f : kFaces) {
          if (occupied(x + f.dx, y + f.dy, z + f.dz)) continue;
          uint32_t id[4];
          for (int k = 0; k < 4; ++k) id[k] = vertex(x + f.c[k][0], y + f.c[k][1], z + f.c[k][2]);
          mesh.triangles.push_back({id[0], id[1], id[2]});
          mesh.triangles.push_back({id[0], id[2], id[3]});
          mesh.triangle_view.push_back(-1);
          mesh.triangle_view.push_back(-1);
        }
      }
    }
  }
  return mesh;
}

void WriteVoxelCentersPly(const std::filesystem::path& path,
                          const VoxelHull& hull,
                          PlyFormat format) {
  AtomicWriteFile(path, Encode(hull.OccupiedCenters(), nullptr, format));
}

void WriteVoxelCubesPly(const std::filesystem::path& path,
                        const VoxelHull& hull,
                        PlyFormat format) {
  WriteMeshPly(path, VoxelSurfaceMesh(hull), format);
}

void WriteMeshPly(const std::filesystem::path& path, const HullMesh& mesh, PlyFormat format) {
  AtomicWriteFile(path, Encode(mesh.vertices, &mesh.triangles, format));
}

}  // namespace irbench
