#pragma once
/// \file VTK output readable by ParaView: XML unstructured grids (.vtu, raw appended binary)
/// and legacy VTK files (.vtk, binary), both with one vertex cell per particle, and .pvd
/// collections for time series.

#include <filesystem>
#include <string>
#include <vector>

#include <sph/core/particle_set.h>
#include <sph/io/frame_format.h>

namespace sph {

/// Writes the particles to a .vtu file (atomically). Points are the positions (z = 0 in 2D);
/// point fields: those in `fields`, in the set's field order (velocity, density, pressure,
/// id (UInt64), initial_position, then added fields), vectors with 3 components. Floating-point
/// fields are Float32 for float runs and Float64 for double runs. The grid's FieldData holds TimeValue (Float64, one
/// value): `time`, which ParaView shows as the frame's time.
template <int D, std::floating_point R>
void write_vtu(const std::filesystem::path& path, const ParticleSet<D, R>& particles, double time = 0,
               const FrameFields& fields = {});

/// Writes the particles to a legacy VTK file (atomically): "# vtk DataFile Version 4.2", BINARY
/// (big-endian, as the legacy format requires), DATASET UNSTRUCTURED_GRID with one vertex cell
/// per particle, FIELD FieldData with TimeValue (double) = `time`, POINTS float (float runs) or
/// double (double runs), then POINT_DATA with one FIELD block of the arrays in `fields`, in the
/// set's field order: velocity (3 components), density, pressure (float or double), id
/// (unsigned_int), initial_position (3), then added fields.
template <int D, std::floating_point R>
void write_legacy_vtk(const std::filesystem::path& path, const ParticleSet<D, R>& particles, double time,
                      const FrameFields& fields = {});

/// One entry of a .pvd time series.
struct PvdEntry {
  double time;
  std::string file;  ///< relative to the .pvd file
};

/// Writes a .pvd collection listing the frames (atomically).
void write_pvd(const std::filesystem::path& path, const std::vector<PvdEntry>& entries);

}  // namespace sph
