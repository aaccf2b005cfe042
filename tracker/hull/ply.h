#pragma once
// PLY output of hulls for MeshLab and Blender: voxel centres as a point cloud,
// voxels as cubes, the polyhedral hull as a triangle mesh. Coordinates are
// world metres, z up. Files are written atomically (a temporary name in the
// same folder, then rename; common/atomic_file.h).

#include <filesystem>

#include "tracker/hull/polyhedral_hull.h"
#include "tracker/hull/voxel_hull.h"

namespace irbench {

enum class PlyFormat { kAscii, kBinaryLittleEndian };

// The centres of the occupied voxels as vertices (float x y z), no faces.
void WriteVoxelCentersPly(const std::filesystem::path& path,
                          const VoxelHull& hull,
                          PlyFormat format = PlyFormat::kBinaryLittleEndian);

// Every occupied voxel as a cube: only the faces between an occupied and an
// empty voxel (the surface of the occupied set), two triangles per face,
// outward wound, vertices shared within the lattice.
void WriteVoxelCubesPly(const std::filesystem::path& path,
                        const VoxelHull& hull,
                        PlyFormat format = PlyFormat::kBinaryLittleEndian);

// A triangle mesh (float x y z vertices; uchar-counted uint32 index lists).
void WriteMeshPly(const std::filesystem::path& path,
                  const HullMesh& mesh,
                  PlyFormat format = PlyFormat::kBinaryLittleEndian);

// The surface of the occupied voxels as a mesh (as WriteVoxelCubesPly writes).
HullMesh VoxelSurfaceMesh(const VoxelHull& hull);

}  // namespace irbench
