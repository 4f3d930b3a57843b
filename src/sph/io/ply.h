#pragma once
/// \file PLY point clouds (.ply, binary little-endian) for Blender and Houdini.

#include <filesystem>

#include <sph/core/particle_set.h>
#include <sph/io/frame_format.h>

namespace sph {

/// Writes the particles to a binary little-endian PLY file (atomically):
///
///   ply
///   format binary_little_endian 1.0
///   comment sph frame
///   comment time 0.125              the simulated time, s (shortest text that reads back exactly)
///   element vertex N
///   property float x / y / z        position (z = 0 in 2D)
///   property float vx / vy / vz     velocity            (if in `fields`)
///   property float density                              (if in `fields`)
///   property float pressure                             (if in `fields`)
///   property uint id                                    (if in `fields`)
///   property float x0 / y0 / z0     initial position    (if in `fields`)
///   property float NAME             an added Real field (if in `fields`)
///   property float NAME_x / _y / _z an added Vector field (if in `fields`)
///   end_header
///
/// then one record per particle. Everything is single precision whatever the run's precision:
/// that is what Blender's and Houdini's importers read as attributes.
template <int D, std::floating_point R>
void write_ply(const std::filesystem::path& path, const ParticleSet<D, R>& particles, double time,
               const FrameFields& fields = {});

}  // namespace sph
