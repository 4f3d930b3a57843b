#pragma once
/// \file Run directories as `sph run -o DIR` leaves them, and the facts about a run a viewer
/// needs (dimension, box, particle radius, mass), for `sph render` and `sph view`. A compare
/// directory (`sph compare -o DIR`) holds one run directory per neighbor mode; run_directories()
/// finds them.

#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <sph/scene/scene_desc.h>

namespace sph {

/// The columns of bodies.csv: the frame, its time (s), the body's index in Obstacles[], its centre
/// of mass (m), orientation (unit quaternion w, x, y, z), velocity (m/s), angular velocity
/// (rad/s), and the fluid's mean force (N) and moment about the centre of mass (N m) over the
/// frame's last step (2D: z = 0, the moment about z, per metre of depth).
inline constexpr const char* kBodyColumns[] = {"frame", "time", "obstacle", "x",  "y",  "z",  "qw", "qx",
                                               "qy",    "qz",   "vx",       "vy", "vz", "wx", "wy", "wz",
                                               "fx",    "fy",   "fz",       "mx", "my", "mz"};

/// One row of DIR/bodies.csv: a floating body where it was at a frame.
struct BodyPoseRow {
  double time = 0;  ///< the frame's time, s
  std::size_t obstacle = 0;
  std::array<double, 3> position{};               ///< centre of mass, m (z = 0 in 2D)
  std::array<double, 4> orientation{1, 0, 0, 0};  ///< unit quaternion w, x, y, z
  std::size_t frame = 0;                          ///< the frame's number
};

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
  /// DIR/bodies.csv's rows (a scene with floating bodies), in the file's order; empty without one.
  /// open_run_directory checks that each floating body has a row at every frame.
  std::vector<BodyPoseRow> bodies;
};

/// Reads a bodies.csv (kBodyColumns). Throws sph::Error naming the file and the line if its header
/// or a row is not what FrameWriter writes.
std::vector<BodyPoseRow> read_body_rows(const std::filesystem::path& file);

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

/// Refuses an output directory given as "" (which would mean the current directory) or as the
/// root of the file system (whose files a run or a render would replace): throws sph::Error
/// naming `option` (e.g. "-o/--output", "output") and what is expected.
void check_output_path(const std::string& path, const std::string& option);

/// True for the names of the files `sph render` makes in its output directory:
/// frame_NNNNNN.png (6 to 12 digits) and movie.mp4. A render removes only these (and a new run
/// removes only these from DIR/render), never a user's other files.
bool is_render_output(const std::string& file_name);

/// True for the names of the files `sph surface` (and `sph run --surface`) make in their output
/// directory: surface_NNNNNN.ply, .obj and .vdb (6 to 12 digits); the only files they replace.
bool is_surface_output(const std::string& file_name);

// --- Run identity --------------------------------------------------------------------------

/// The file of a run directory that names the run that owns it (docs/reliability.md, "Run
/// directories"): a JSON object {"run_id": ..., "scene_fingerprint": ...}, written when the run
/// starts and kept when it is resumed. scene.json stays a plain scene (sph run reads it), so its
/// identity lives beside it; summary.json and the checkpoint record the same two values.
inline constexpr const char* kRunIdentityFile = "run.json";

/// Who a run is: made once when a new run starts, kept by every session that resumes it.
struct RunIdentity {
  /// "YYYYMMDDTHHMMSSZ-PID-RRRRRRRR": the start time (UTC), the process id and 32 random bits.
  std::string run_id;
  /// scene_fingerprint() of the run's effective scene.
  std::string scene_fingerprint;
};

/// A new run id (see RunIdentity::run_id); two calls never give the same id.
std::string new_run_id();

/// The fingerprint of an effective scene (scene_text(desc)): 16 hex digits of the FNV-1a 64-bit
/// hash of its JSON, keys sorted, without Configuration.numberOfSteps (which `--resume --steps`
/// changes within one run), then of the bytes of each mesh file its obstacles name
/// (geometryFile). Two scenes that would run the same way give the same fingerprint.
std::string scene_fingerprint(const std::string& scene_json);

/// Writes DIR/run.json (atomically). Throws sph::Error naming the path.
void write_run_identity(const std::filesystem::path& dir, const RunIdentity& id);

/// For `sph run --resume DIR`: checks that the files of DIR belong to the run of the checkpoint
/// (identity `checkpoint`): run.json and summary.json name its run id, and scene.json (if there)
/// has its scene fingerprint. Throws sph::Error naming the file and both ids otherwise (a
/// checkpoint copied into another run's directory), or if run.json is missing or unreadable.
void check_run_identity(const std::filesystem::path& dir, const RunIdentity& checkpoint);

/// What DIR/summary.json says about a run that ended, if it is there.
struct RunEnd {
  std::string status;      ///< "completed", "completed with warnings: ...", "interrupted by ...", "failed: ..."
  std::int64_t steps = 0;  ///< steps done
  /// The run did all its steps (status "completed" or "completed with warnings..."): it is
  /// finished, and only a larger --steps continues it.
  bool finished() const { return status.rfind("completed", 0) == 0; }
};

/// DIR/summary.json's status and steps; nullopt if there is no summary.json. Throws sph::Error
/// naming the file if it is not a summary (not JSON, no status or steps).
std::optional<RunEnd> read_run_end(const std::filesystem::path& dir);

/// If DIR holds the checkpoint of a run that has not finished (interrupted, killed or failed: no
/// summary.json saying it completed), a description of it such as "an interrupted run's
/// checkpoint (at step 40; interrupted by SIGINT after step 40 of 100)"; else nullopt.
std::optional<std::string> unfinished_run(const std::filesystem::path& dir);

}  // namespace sph
