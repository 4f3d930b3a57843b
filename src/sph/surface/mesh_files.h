#pragma once
/// \file Surface files (docs/visualization.md, "Surfaces"): binary PLY and OBJ meshes, and an
/// OpenVDB level set, each written atomically (whole or not at all).

#include <cstddef>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include <sph/surface/surface.h>

namespace sph {

/// Binary little-endian PLY: `element vertex` (float x y z, and nx ny nz in 3D), then in 3D
/// `element face` (list uchar int vertex_indices): triangles counter-clockwise seen from outside
/// in 3D, segments (two-vertex faces, as meshio reads lines) with the fluid on their left in 2D.
/// Comments carry the time and the voxel size.
void write_surface_ply(const std::filesystem::path& path, const SurfaceMesh& mesh, double time);

/// Wavefront OBJ: `v` lines, then in 3D `vn` and `f a//a b//b c//c`, in 2D one `l` line per
/// polyline (a closed one repeats its first vertex).
void write_surface_obj(const std::filesystem::path& path, const SurfaceMesh& mesh, double time);

/// An OpenVDB file holding one float grid named `grid_name`, class level set: the signed
/// distance to the 3D mesh (negative inside) in a narrow band of 3 voxels each side, voxel size
/// mesh.voxel_size, world coordinates as the mesh's. Refused (sph::Error) for a 2D mesh.
void write_surface_vdb(const std::filesystem::path& path, const SurfaceMesh& mesh, double time,
                       std::string_view grid_name = "surface");

/// Which surface files a frame gets.
struct SurfaceFormats {
  bool ply = true, obj = true, vdb = true;
};

/// "all" or a comma list of ply, obj and vdb (each at most once); throws sph::Error naming
/// `flag` otherwise.
SurfaceFormats parse_surface_formats(std::string_view list, const std::string& flag = "--surface-format");

/// What `sph run --surface` writes with each frame.
struct SurfaceOutput {
  SurfaceSettings settings;  ///< its spacing is set from the scene's particleRadius
  SurfaceFormats formats;
};

/// Writes frame `index`'s surface files to `dir` (which must exist): surface_NNNNNN.ply, .obj
/// and, in 3D, .vdb, as `formats` selects (2D surfaces have no level set). Returns the paths
/// written.
std::vector<std::filesystem::path> write_surface_frame(const std::filesystem::path& dir, std::size_t index,
                                                       const SurfaceMesh& mesh, double time,
                                                       const SurfaceFormats& formats);

}  // namespace sph
