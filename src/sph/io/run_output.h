#pragma once
/// \file RunOutput: everything a run writes to its output directory.
///
///   DIR/frames.pvd             time series of the .vtu frames for ParaView (when vtu is among
///                              the formats; rewritten after every frame)
///   DIR/frames/frame_NNNNNN.EXT  particle frames in each format of Configuration.outputFormats
///                              (.vtu, .vtk, .ply; see FrameWriter)
///   DIR/stats.csv              one row per step (see kStatsColumns)
///   DIR/summary.json           written at the end: scene, mode, steps, timings, status
///   DIR/scene.json             the effective scene (after --set overrides)
///   DIR/run.json               the run's id and scene fingerprint (run_directory.h, RunIdentity)
///   DIR/checkpoint.sphc        the latest checkpoint (see checkpoint.h), if one was written
/// Every file appears whole or not at all.

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include <sph/io/frame_writer.h>
#include <sph/io/run_directory.h>
#include <sph/io/vtk.h>
#include <sph/scene/scene_desc.h>
#include <sph/solver/simulation.h>

namespace sph {

/// What one row of stats.csv is made of: a step's StepInfo and what was measured after it.
struct StepStats {
  const StepInfo& info;
  double kinetic_energy = 0;  ///< of the particles after the step, J (J/m in 2D)
  double max_speed = 0;       ///< m/s
  double t_output = 0;        ///< wall seconds spent writing the step's output
};

/// How a stats.csv column writes its value.
enum class StatsFormat {
  Count,  ///< an unsigned integer
  Real9,  ///< a real, 9 significant digits
  Real6,  ///< a real, 6 significant digits
};

/// One column of stats.csv (README.md, "What a run writes", explains each): its name, how it is
/// written, and its value for a step (`count` for StatsFormat::Count, `real` otherwise).
/// Audit columns are empty in the rows of steps that were not audited.
struct StatsColumn {
  std::string_view name;
  StatsFormat format = StatsFormat::Count;
  bool audit_only = false;
  std::uint64_t (*count)(const StepStats&) = nullptr;
  double (*real)(const StepStats&) = nullptr;
};

namespace detail {
constexpr StatsColumn count_column(std::string_view name, std::uint64_t (*f)(const StepStats&), bool audit = false) {
  return {name, StatsFormat::Count, audit, f, nullptr};
}
constexpr StatsColumn real_column(std::string_view name, StatsFormat format, double (*f)(const StepStats&),
                                  bool audit = false) {
  return {name, format, audit, nullptr, f};
}
}  // namespace detail

/// The columns of stats.csv, in order: the one list that the header, every row, the Python
/// module's `Simulation.counters` and the readers of a run's stats derive from. `step` is the
/// number of steps done after the row's step (1 for the first row, numberOfSteps for the last),
/// as summary.json's "steps" and --steps count them; `time` is the simulated time then. The three
/// audit columns (missed_pairs, particles_missing, max_missed_penetration) are empty unless the
/// run audits. Then eight of the health monitor's statistics of the step (HealthStats;
/// docs/reliability.md), and the boundary particles' lists: entries stored, and (audited runs)
/// the fluid-boundary pairs within h they missed (0 and empty with penalty walls). Last, the work
/// of the step's list building: entries written by (re)builds and insertions, the tracked modes'
/// insertions into and removals from other particles' lists and lists that outgrew their room,
/// and the lists' skin (m; 0 in the modes without one). Then the step's time step (s), and DFSPH's
/// solves: the constant-density solve's iterations and final average compression (%), the
/// divergence solve's iterations and final average divergence error (% per second), the wall
/// seconds of the solves (t_solve: DFSPH's two and the implicit viscosity's); 0 with WCSPH.
/// Last, the implicit viscosity solve's iterations and final residual (% of its starting one);
/// 0 with the explicit viscosity.
inline constexpr StatsColumn kStatsColumns[] = {
    detail::count_column("step", [](const StepStats& s) { return static_cast<std::uint64_t>(s.info.step + 1); }),
    detail::real_column("time", StatsFormat::Real9, [](const StepStats& s) { return s.info.time; }),
    detail::count_column("particles", [](const StepStats& s) { return static_cast<std::uint64_t>(s.info.particles); }),
    detail::real_column("kinetic_energy", StatsFormat::Real9, [](const StepStats& s) { return s.kinetic_energy; }),
    detail::real_column("max_speed", StatsFormat::Real9, [](const StepStats& s) { return s.max_speed; }),
    detail::real_column("mean_neighbors", StatsFormat::Real6,
                        [](const StepStats& s) {
                          return s.info.particles ? static_cast<double>(s.info.neighbors.pairs_stored) /
                                                        static_cast<double>(s.info.particles)
                                                  : 0.0;
                        }),
    detail::count_column("lists_rebuilt", [](const StepStats& s) { return s.info.neighbors.lists_rebuilt; }),
    detail::count_column("pairs_stored", [](const StepStats& s) { return s.info.neighbors.pairs_stored; }),
    detail::count_column("pairs_within_h", [](const StepStats& s) { return s.info.pairs_within_h; }),
    detail::count_column(
        "missed_pairs", [](const StepStats& s) { return s.info.audit.missed_pairs; }, true),
    detail::count_column(
        "particles_missing", [](const StepStats& s) { return s.info.audit.particles_missing; }, true),
    detail::real_column(
        "max_missed_penetration", StatsFormat::Real6, [](const StepStats& s) { return s.info.audit.max_penetration; },
        true),
    detail::real_column("t_grid", StatsFormat::Real6, [](const StepStats& s) { return s.info.seconds.grid; }),
    detail::real_column("t_lists", StatsFormat::Real6, [](const StepStats& s) { return s.info.seconds.lists; }),
    detail::real_column("t_density", StatsFormat::Real6, [](const StepStats& s) { return s.info.seconds.density; }),
    detail::real_column("t_forces", StatsFormat::Real6, [](const StepStats& s) { return s.info.seconds.forces; }),
    detail::real_column("t_integrate", StatsFormat::Real6, [](const StepStats& s) { return s.info.seconds.integrate; }),
    detail::real_column("t_output", StatsFormat::Real6, [](const StepStats& s) { return s.t_output; }),
    detail::count_column("outside", [](const StepStats& s) { return s.info.health.outside; }),
    detail::real_column("outside_depth", StatsFormat::Real6,
                        [](const StepStats& s) { return s.info.health.outside_depth; }),
    detail::count_column("inside_solid", [](const StepStats& s) { return s.info.health.inside_solid; }),
    detail::real_column("inside_depth", StatsFormat::Real6,
                        [](const StepStats& s) { return s.info.health.inside_depth; }),
    detail::real_column("max_mach", StatsFormat::Real6, [](const StepStats& s) { return s.info.health.max_mach; }),
    detail::real_column("rho_min", StatsFormat::Real6, [](const StepStats& s) { return s.info.health.rho_min; }),
    detail::real_column("rho_max", StatsFormat::Real6, [](const StepStats& s) { return s.info.health.rho_max; }),
    detail::real_column("energy", StatsFormat::Real9, [](const StepStats& s) { return s.info.health.energy; }),
    detail::count_column("boundary_pairs_stored",
                         [](const StepStats& s) { return s.info.neighbors.boundary_pairs_stored; }),
    detail::count_column(
        "boundary_missed_pairs", [](const StepStats& s) { return s.info.boundary_audit.missed_pairs; }, true),
    detail::count_column("entries_rebuilt", [](const StepStats& s) { return s.info.neighbors.entries_rebuilt; }),
    detail::count_column("list_insertions", [](const StepStats& s) { return s.info.neighbors.insertions; }),
    detail::count_column("list_removals", [](const StepStats& s) { return s.info.neighbors.removals; }),
    detail::count_column("list_overflows", [](const StepStats& s) { return s.info.neighbors.overflows; }),
    detail::real_column("skin", StatsFormat::Real6, [](const StepStats& s) { return s.info.neighbors.skin; }),
    detail::real_column("dt", StatsFormat::Real9, [](const StepStats& s) { return s.info.dt; }),
    detail::count_column(
        "solver_iterations",
        [](const StepStats& s) { return static_cast<std::uint64_t>(s.info.density_solve.iterations); }),
    detail::real_column("density_error", StatsFormat::Real6,
                        [](const StepStats& s) { return s.info.density_solve.error; }),
    detail::count_column(
        "divergence_iterations",
        [](const StepStats& s) { return static_cast<std::uint64_t>(s.info.divergence_solve.iterations); }),
    detail::real_column("divergence_error", StatsFormat::Real6,
                        [](const StepStats& s) { return s.info.divergence_solve.error; }),
    detail::real_column("t_solve", StatsFormat::Real6, [](const StepStats& s) { return s.info.seconds.solve; }),
    detail::count_column(
        "viscosity_iterations",
        [](const StepStats& s) { return static_cast<std::uint64_t>(s.info.viscosity_solve.iterations); }),
    detail::real_column("viscosity_error", StatsFormat::Real6,
                        [](const StepStats& s) { return s.info.viscosity_solve.error; }),
};

/// The header line of stats.csv: the column names, comma-separated.
std::string stats_header();
/// The stats.csv row of a step (without the line's end), each column as kStatsColumns writes it.
std::string stats_row(const StepStats& stats);

/// Facts about the run that are not in the scene.
struct RunInfo {
  std::string mode;  ///< neighbor mode name
  int threads = 1;
};

/// The files in `dir` that a new run replaces (prepare_output_directory removes them), in a fixed
/// order: frames.pvd, solids.pvd, stats.csv, summary.json, scene.json, checkpoint.sphc, run.json,
/// boundary.vtu, bodies.csv, view.html, render/frame_NNNNNN.png and movie.mp4,
/// surface/surface_NNNNNN.ply, .obj and .vdb, frames/frame_NNNNNN.vtu, .vtk and .ply,
/// frames/solids_NNNNNN.vtp and .ply; those that exist. Empty if `dir` does not exist.
std::vector<std::filesystem::path> files_a_run_replaces(const std::filesystem::path& dir);

/// Checks, before anything is written, that a new run may start in `dir` (sph run -o DIR,
/// sph.run(output=DIR)). Throws sph::Error if it is "" or the root of the file system
/// (check_output_path, naming `output_option`), or, naming `dir`, unless `overwrite`: if it holds the checkpoint of a
/// run that did not finish (unfinished_run; `resume_hint`, e.g. "continue it with sph run --resume DIR", is said first
/// if not empty), or if it is not a run's directory (no run.json) and yet holds files a run replaces
/// (files_a_run_replaces: a scene.json or stats.csv of the user's own, which the run would overwrite without a word).
/// `overwrite_option` names what allows it in the message ("--overwrite", "overwrite=True").
void check_new_run_directory(const std::filesystem::path& dir, bool overwrite, const std::string& output_option,
                             const std::string& overwrite_option, const std::string& resume_hint);

/// Creates `dir` if needed and checks that files can be created in it; removes the files a
/// previous run left there (frames, stats, summary, run.json, and the pictures of `sph render`
/// and `sph view`: render/frame_NNNNNN.png, render/movie.mp4, view.html; the surfaces of `sph surface`
/// and `sph run --surface`: surface/surface_NNNNNN.ply, .obj, .vdb). Throws sph::Error naming the path.
void prepare_output_directory(const std::filesystem::path& dir);

/// For a resumed run: checks that `dir` is a directory where files can be created, and
/// removes the temporary files a killed run may have left (never a finished file). Throws
/// sph::Error naming the path.
void prepare_resume_directory(const std::filesystem::path& dir);

template <int D, std::floating_point R>
class RunOutput {
 public:
  /// `dir` must have been prepared with prepare_output_directory. `run_id`: the id of the run
  /// continued (from its checkpoint), or empty for a new run (a new_run_id()).
  RunOutput(std::filesystem::path dir, const SceneDesc& desc, RunInfo info, std::string run_id = {});
  ~RunOutput();

  /// Writes frame 0 (the initial state) and scene.json, and starts stats.csv.
  void begin(const Simulation<D, R>& sim);
  /// Instead of begin(), continues the run that wrote a checkpoint (`sim` restored from it,
  /// `in` positioned at what save_state() wrote): restores the frame list and the totals,
  /// removes the frames written after the checkpoint, keeps the stats rows of the steps before
  /// it (from stats.csv, or from the partial file a killed run left) and removes summary.json
  /// until finish() writes it again. Returns a warning ("" if none), e.g. missing stats rows.
  std::string resume(const Simulation<D, R>& sim, StateReader& in);
  /// Writes the frame list and the totals for a checkpoint of `sim`, `wall_seconds` into this
  /// session. Flushes stats.csv's partial file first, so that every row before the checkpoint
  /// is on disk.
  void save_state(StateWriter& out, const Simulation<D, R>& sim, double wall_seconds);
  /// Wall seconds of the run's earlier sessions (before the checkpoint it resumed from).
  double earlier_wall_seconds() const { return earlier_wall_seconds_; }
  /// After each step: writes a frame if one is due (FrameSchedule: every output.every_steps
  /// steps or at output.fps frames per simulated second, and at the last step), then the
  /// step's stats row. Returns the seconds spent writing.
  double after_step(const Simulation<D, R>& sim, const StepInfo& info, bool last);
  /// Closes stats.csv and writes summary.json with `status` ("completed" or an error message);
  /// `wall_seconds` of this session (earlier sessions of a resumed run are added).
  void finish(const Simulation<D, R>& sim, const std::string& status, double wall_seconds);

  std::size_t frames_written() const { return frames_.frames_written(); }
  /// The time of the next frame on the outputFps schedule, s (infinity without one).
  double next_frame_time() const { return frames_.next_frame_time(); }
  /// The run's id and scene fingerprint, as run.json, summary.json and checkpoints record them.
  const RunIdentity& identity() const { return identity_; }
  /// Audit totals over the steps so far: missed pairs summed, deepest penetration (zero
  /// without auditing).
  const ListAudit& audit_totals() const { return audit_; }
  /// Audited steps with at least one missed pair.
  std::uint64_t audit_steps_with_misses() const { return audit_steps_with_misses_; }
  /// Fluid-boundary pairs within h the boundary lists missed, summed over the audited steps.
  std::uint64_t boundary_missed_pairs() const { return boundary_missed_; }

 private:
  void open_stats();
  /// boundary.vtu: the boundary particles' positions, ids (sample indices) and psi, once.
  void write_boundary(const Simulation<D, R>& sim) const;

  std::filesystem::path dir_;
  const SceneDesc& desc_;
  RunInfo info_;
  RunIdentity identity_;
  FrameWriter<D, R> frames_;
  std::ofstream stats_;
  std::filesystem::path stats_tmp_;
  PhaseTimes totals_;
  std::uint64_t totals_lists_rebuilt_ = 0;
  ListAudit audit_;  // summed missed pairs, largest penetration
  std::uint64_t audit_steps_with_misses_ = 0;
  std::uint64_t boundary_missed_ = 0, boundary_steps_with_misses_ = 0;  // boundary lists (audited runs)
  double output_seconds_ = 0;
  double earlier_wall_seconds_ = 0;
  std::vector<std::int64_t> resumed_at_;  // steps this run was resumed from, in order
  std::int64_t last_checkpoint_step_ = -1;
  bool finished_ = false;
};

extern template class RunOutput<2, float>;
extern template class RunOutput<2, double>;
extern template class RunOutput<3, float>;
extern template class RunOutput<3, double>;

}  // namespace sph
