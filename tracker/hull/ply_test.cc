#include "tracker/hull/ply.h"

#include <gtest/gtest.h>

#include <cstring>
#include <fstream>
#include <map>
#include <sstream>

#include "tracker/hull/hull_test_util.h"

namespace irbench {
namespace {
namespace fs = std::filesystem;

std::string Read(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

fs::path TempDir() {
  const fs::path dir = fs::temp_directory_path() / "irbench_test_hull_ply";
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

VoxelHull SmallHull() {
  VoxelHull hull;
  hull.origin_m = {-0.1, 0.2, 0.0};
  hull.voxel_size_m = 0.1;
  hull.nx = 3, hull.ny = 2, hull.nz = 2;
  hull.occupied = {1, 1, 0, 0, 1, 0, 0, 0, 0, 0, 1, 1};
  hull.occupied_count = 5;
  return hull;
}

TEST(PlyTest, VoxelSurfaceEnclosesTheVoxelVolume) {
  const VoxelHull hull = SmallHull();
  const HullMesh surface = VoxelSurfaceMesh(hull);
  // A closed, outward-wound surface: its divergence volume is the voxel count.
  EXPECT_NEAR(MeshVolume(surface), hull.VolumeM3(), 1e-12);
  // Each edge is used once in each direction (closed and consistently wound).
  std::map<std::pair<uint32_t, uint32_t>, int> edges;
  for (const auto& t : surface.triangles) {
    for (int k = 0; k < 3; ++k) ++edges[{t[k], t[(k + 1) % 3]}];
  }
  for (const auto& [e, n] : edges) EXPECT_EQ(edges.count({e.second, e.first}), 1u);
}

TEST(PlyTest, AsciiAndBinaryRoundTrip) {
  const fs::path dir = TempDir();
  const VoxelHull hull = SmallHull();
  WriteVoxelCentersPly(dir / "c.ply", hull, PlyFormat::kAscii);
  const std::string ascii = Read(dir / "c.ply");
  const size_t end = ascii.find("end_header\n");
  ASSERT_NE(end, std::string::npos);
  EXPECT_EQ(ascii.rfind("ply\nformat ascii 1.0\n", 0), 0u);
  EXPECT_NE(ascii.find("element vertex 5\n"), std::string::npos);
  std::istringstream body(ascii.substr(end + 11));
  const auto centres = hull.OccupiedCenters();
  for (const auto& c : centres) {
    double x, y, z;
    body >> x >> y >> z;
    EXPECT_NEAR(x, c.x(), 1e-6);
    EXPECT_NEAR(y, c.y(), 1e-6);
    EXPECT_NEAR(z, c.z(), 1e-6);
  }

  const HullMesh surface = VoxelSurfaceMesh(hull);
  WriteVoxelCubesPly(dir / "cubes.ply", hull);
  const std::string bin = Read(dir / "cubes.ply");
  const size_t header = bin.find("end_header\n") + 11;
  EXPECT_NE(bin.find("format binary_little_endian 1.0\n"), std::string::npos);
  EXPECT_NE(bin.find("element face " + std::to_string(surface.triangles.size()) + "\n"),
            std::string::npos);
  ASSERT_EQ(bin.size(), header + 12 * surface.vertices.size() + 13 * surface.triangles.size());
  float xyz[3];
  std::memcpy(xyz, bin.data() + header + 12, 12);
  EXPECT_NEAR(xyz[0], surface.vertices[1].x(), 1e-6);
  EXPECT_NEAR(xyz[2], surface.vertices[1].z(), 1e-6);
  uint32_t idx[3];
  std::memcpy(idx, bin.data() + header + 12 * surface.vertices.size() + 1, 12);
  EXPECT_EQ(bin[header + 12 * surface.vertices.size()], 3);
  EXPECT_EQ(idx[0], surface.triangles[0][0]);
  EXPECT_EQ(idx[2], surface.triangles[0][2]);

  WriteMeshPly(dir / "mesh.ply", surface, PlyFormat::kAscii);
  EXPECT_NE(Read(dir / "mesh.ply").find("\n3 "), std::string::npos);
  // Atomic: only the three final files, no temporaries left behind.
  int files = 0;
  for (const auto& e : fs::directory_iterator(dir)) files += e.is_regular_file() ? 1 : 0;
  EXPECT_EQ(files, 3);
  // Rewriting replaces the file in place.
  WriteVoxelCentersPly(dir / "c.ply", hull, PlyFormat::kBinaryLittleEndian);
  EXPECT_NE(Read(dir / "c.ply").find("binary_little_endian"), std::string::npos);
}

}  // namespace
}  // namespace irbench
