#pragma once
/// \file The scene's obstacles as surfaces, where they are at a time: ParaView's XML polydata
/// (.vtp) and PLY meshes, written with each frame (FrameWriter) so that a moving paddle or stirrer
/// plays with the particles (DIR/solids.pvd next to DIR/frames.pvd).

#include <filesystem>
#include <span>
#include <vector>

#include <sph/solver/params.h>

namespace sph {

/// Writes the obstacles (each box at rest) placed by `poses` (motion.h; one per obstacle, missing
/// ones: at rest) at time t to a .vtp file (atomically):
/// 3D: each box's 8 corners and 6 quads (outward, counter-clockwise seen from outside); 2D: each
/// box's 4 corners (z = 0) and one quad. An obstacle with a shape (`shapes[k]`, shape.h) gives its
/// own vertices and faces: a mesh's triangles, a polygon as one polygon cell. Cell data
/// "obstacle": the obstacle's index in Obstacles[]; field data TimeValue: t.
template <int D>
void write_solids_vtp(const std::filesystem::path& path, const std::vector<Box<D>>& obstacles,
                      std::span<const RigidPose<D>> poses, double t, std::span<const ObstacleShape<D>> shapes = {});

/// The same surfaces as an ASCII PLY mesh (atomically), for Blender and Houdini beside the PLY
/// frames: `element vertex` (x y z: the corners, z = 0 in 2D), `element face` (vertex_indices,
/// the same polygons), `comment time T` in the header.
template <int D>
void write_solids_ply(const std::filesystem::path& path, const std::vector<Box<D>>& obstacles,
                      std::span<const RigidPose<D>> poses, double t, std::span<const ObstacleShape<D>> shapes = {});

}  // namespace sph
