#pragma once
/// \file Run directories as `sph run -o DIR` leaves them, and the facts about a run a viewer
/// needs (dimension, box, particle radius, mass), for `sph render` and `sph view`. A compare
/// directory (`sph compare -o DIR`) holds one run directory per neighbor mode; run_directories()
/// finds them.

#include <array>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <sph/scene/scene_desc.h>

namespace sph {

/// A run directory as `sph run -o DIR` leaves it.
struct RunDirectory {
  std::filesystem::path dir;
  /// The neighbor mode (Configuration.neighbors) for a run of a compare directory (its parent
  /// holds runs.txt), else the scene name.
  std::string label;
  SceneDesc scene;  ///< read from DIR/scene.json (the effective scene)
  int dimension = 3;
  /// From the scene: Configuration.particleRadius, kernelRadius, the particle mass
  /// (Fluid.particleMass or the lattice mass the scene reader derives), Fluid.density0.
  double particle_radius = 0, kernel_radius = 0, particle_mass = 0, rest_density = 0;
  std::array<double, 3> box_lo{}, box_hi{};  ///< the container (z = 0 in 2D)
  /// Frame files in order (frames/frame_000000.EXT, ...), of the format chosen by
  /// open_run_directory.
  std::vector<std::filesystem::path> frames;
  FrameFormat format = FrameFormat::Vtu;
};

/// Opens a run directory: reads DIR/scene.json and lists the frames of `format`, or of the first
/// format present in the order vtu, vtk, ply. Throws sph::Error naming the path if DIR is
/// missing, is not a run directory (no scene.json), or holds no frames (of `format`).
RunDirectory open_run_directory(const std::filesystem::path& dir, std::optional<FrameFormat> format = {});

/// The frame files of `format` in DIR/frames, in order: frames/frame_000000.EXT,
/// frame_000001.EXT, ... (6 or more digits). Other files there (temporaries of a killed run,
/// frames of other formats, notes) are ignored; an empty list if there are none. Throws
/// sph::Error naming the directory if the numbering has a gap (a frame file was removed) or two
/// files hold the same number (frame_000001.vtu and frame_0000001.vtu).
std::vector<std::filesystem::path> list_frames(const std::filesystem::path& dir, FrameFormat format);

/// The file of a compare directory that names its run directories, in order: plain UTF-8 text,
/// one subdirectory name per line (no '/', each once, at least one; blank lines and trailing
/// spaces are ignored), e.g.
///
///   standard
///   adaptive
///   verlet
///
/// Each named subdirectory is a run directory (sph run -o DIR layout, with scene.json).
inline constexpr const char* kRunListFile = "runs.txt";

/// Writes DIR/runs.txt (atomically) naming `names` in this order (for sph compare).
void write_run_list(const std::filesystem::path& dir, const std::vector<std::string>& names);

/// The run directories under `dir`: {dir} itself if it is a run (has scene.json); for a compare
/// directory (has runs.txt, see kRunListFile), its runs in the order runs.txt lists them (the
/// order `sph compare` ran them, standard first). Throws sph::Error naming `dir` if it is
/// neither, or naming runs.txt if it is malformed or lists a directory that is not a run.
std::vector<std::filesystem::path> run_directories(const std::filesystem::path& dir);

}  // namespace sph
