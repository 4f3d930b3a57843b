#pragma once
/// \file Triangle meshes from files (Obstacles[].geometryFile): OBJ, STL (ASCII or binary) and PLY
/// (ASCII or binary), read through the Open Asset Import Library (assimp, Debian's libassimp-dev):
/// one well-kept reader for the three formats users export from Blender, CAD and scanners.

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <sph/core/vec.h>

namespace sph {

/// A mesh's triangles over its vertices, as the file has them (no transform).
struct TriangleMesh {
  std::vector<Vec<3, double>> vertices;
  std::vector<std::array<std::uint32_t, 3>> triangles;
};

/// The file types read_mesh_file() takes, by extension (lower case, with the dot).
inline constexpr std::array<const char*, 3> kMeshExtensions{".obj", ".stl", ".ply"};

/// Reads the triangles of every mesh in `path` (polygons are split into triangles; points and
/// lines are left out). Vertices at the same position are merged into one (across the file's
/// meshes too), so that a mesh written as separate triangles (STL) or in groups (OBJ) is one
/// connected surface. Throws sph::Error (its message names the file) when the file is missing, is
/// not a regular file, has another extension, is larger than 2 GB, cannot be read, or holds no
/// triangles.
TriangleMesh read_mesh_file(const std::string& path);

}  // namespace sph
