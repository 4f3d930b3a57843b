#pragma once
/// \file VTK output readable by ParaView: XML unstructured grids (.vtu, raw appended binary)
/// with one vertex cell per particle, and .pvd collections for time series.

#include <filesystem>
#include <string>
#include <vector>

#include <sph/core/particle_set.h>

namespace sph {

/// Writes the particles to a .vtu file (atomically). Points are the positions (z = 0 in 2D);
/// point fields: velocity, initial_position (3 components), density, pressure (scalars),
/// id (UInt64). Floating-point fields are Float32 for float runs and Float64 for double runs.
template <int D, std::floating_point R>
void write_vtu(const std::filesystem::path& path, const ParticleSet<D, R>& particles);

/// One entry of a .pvd time series.
struct PvdEntry {
  double time;
  std::string file;  ///< relative to the .pvd file
};

/// Writes a .pvd collection listing the frames (atomically).
void write_pvd(const std::filesystem::path& path, const std::vector<PvdEntry>& entries);

}  // namespace sph
