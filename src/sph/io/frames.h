#pragma once
/// \file Reading back what a run wrote: its frames (.vtu, legacy .vtk and .ply files written by
/// sph), as doubles (FrameData: the one "particle state as doubles" view, also made from a
/// ParticleSet by frame_data_of). The run directories themselves: run_directory.h.

#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <sph/core/particle_set.h>
#include <sph/io/frame_format.h>
#include <sph/io/run_directory.h>

namespace sph {

/// A point field of a frame, as double whatever precision the file stored.
struct FrameField {
  std::string name;            ///< a field of kParticleFields that frames hold, or one a run added
  int components = 1;          ///< 1 or 3
  std::vector<double> values;  ///< `components` values per particle, particle after particle
};

/// One frame read back from a file.
struct FrameData {
  double time = 0;                 ///< simulated time, s
  std::size_t size = 0;            ///< particles
  std::vector<double> position;    ///< 3 coordinates per particle (z = 0 in 2D)
  std::vector<FrameField> fields;  ///< the fields the file holds (the run's --fields)
  /// The field with this name, or nullptr if the file does not hold it.
  const FrameField* field(std::string_view name) const;
};

/// Reads a frame file written by sph; the format comes from the extension (.vtu, .vtk, .ply).
/// Throws sph::Error naming the file if it is missing, unreadable, truncated, of another
/// extension, or not laid out as sph writes it (another program's file of the same format).
/// `time` is 0 for a .vtu written before frames carried their time (no TimeValue). PLY files
/// store single precision whatever the run's precision; .vtu and .vtk files store the run's.
/// Point fields are those of kParticleFields that frames hold and, for a run whose particle set
/// had fields added (ParticleSet::add_field), those given in `added`; any other is refused.
FrameData read_frame(const std::filesystem::path& file, std::span<const FieldSpec> added = {});

/// The field the boundary samples' file (boundary.vtu, Configuration.outputBoundary) holds
/// besides their ids: each sample's psi. Pass it to read_frame as `added` to read that file.
std::span<const FieldSpec> boundary_sample_fields();

/// The particles' state as a frame holds it: positions padded to 3 coordinates, the fields
/// `fields` selects in the set's field order, every value as a double (ids too).
template <int D, std::floating_point R>
FrameData frame_data_of(const ParticleSet<D, R>& particles, double time, const FrameFields& fields = {});

}  // namespace sph
