#pragma once
/// \file RunDriver: one run of a scene, start to end, as `sph run`, `sph compare`, `sph validate`
/// and the benchmarks run it. It builds the simulation, creates and prepares (or, resuming,
/// checks) the output directory, runs the step loop with the output of each step (frames,
/// stats.csv: RunOutput), writes checkpoints on their cadence and on a stop request, and returns
/// how the run ended. It prints nothing: the caller reports through the callbacks and the result.
///
/// A run with no output directory writes nothing and checkpoints nothing: the step loop then
/// adds no work to the steps but the callbacks the caller gives (benchmarks time it).

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <sph/core/timer.h>
#include <sph/io/checkpoint.h>
#include <sph/io/run_output.h>
#include <sph/scene/scene_desc.h>
#include <sph/solver/simulation.h>
#include <sph/surface/mesh_files.h>

namespace sph {

/// How a run ended.
enum class RunStatus {
  Completed,    ///< every step of the scene was done (RunResult::warnings may hold health warnings)
  Interrupted,  ///< a stop request ended it after a step (with a checkpoint if it writes output)
  Failed,       ///< a step or the output threw sph::Error (a blow-up, a full disk)
};

/// "completed", "interrupted", "failed".
std::string_view to_string(RunStatus status);

/// Where a run writes and how often it saves itself.
struct RunSettings {
  /// The run's output directory (frames, stats.csv, summary.json, scene.json, checkpoints);
  /// empty: the run writes nothing.
  std::filesystem::path dir;
  /// A checkpoint every N steps and at the last step (0: only on a stop request, and at the last
  /// step of a resumed run). Recorded in the checkpoint, so that a resumed run goes on as often.
  /// Needs `dir`.
  std::int64_t checkpoint_every = 0;
  /// Health warnings fail the run (`sph run --strict`): the step that raises the first one ends
  /// it, status "failed: WARNING (--strict)".
  bool strict = false;
  /// Also the free surface of every frame written (`sph run --surface`): DIR/surface/
  /// surface_NNNNNN.ply, .obj, .vdb (sph/surface/mesh_files.h). Its spacing is taken from the
  /// scene (2 Configuration.particleRadius). Needs `dir`.
  std::optional<SurfaceOutput> surface{};
  /// The particles keep every field, those no output of the run reads too. Without it a run
  /// keeps the initial positions only when it writes frames (`dir`) that hold them (12 bytes a
  /// particle in float 3D). Python's Simulation sets it (its views and write_frame offer every
  /// field), and so does `sph compare` (its snapshots read the initial positions).
  bool every_field = false;
};

/// What the caller hears during the run. Each is called between steps; any may be empty.
struct RunCallbacks {
  /// Polled after each step but the scene's last (a request during the last step lets the run
  /// complete), with the steps done: a non-empty return (the cause, e.g. "SIGINT") stops the run
  /// there, after a checkpoint if the run writes output.
  std::function<std::string(std::int64_t steps_done)> stop_requested;
  /// After each step's output: the steps done (counted from the start of the run, not of this
  /// session) and the particles.
  std::function<void(std::int64_t steps_done, std::size_t particles)> progress;
  /// Once per kind of health warning, after the step that first raised it (before its output),
  /// with the warning's text (HealthMonitor::warning).
  std::function<void(const std::string& warning)> warning;
};

/// How a run ended, for the caller to report.
struct RunResult {
  RunStatus status = RunStatus::Completed;
  /// The status as summary.json records it: "completed", "completed with warnings: W1; W2",
  /// "interrupted by CAUSE after step K of N", "failed: ERROR" (a --strict warning: "failed:
  /// WARNING (--strict)").
  std::string message;
  std::vector<std::string> warnings;  ///< the health warnings given, in order (also a resumed run's earlier ones)
  std::string error;                  ///< Failed: the error's text
  std::string stop_cause;             ///< Interrupted: what stop_requested returned
  std::int64_t first_step = 0;        ///< steps done when this session started (0 unless resumed)
  std::int64_t steps_done = 0;        ///< steps done at the end
  double wall_seconds = 0;            ///< this session's wall seconds, from the driver's construction
};

/// One run of one scene in dimension D and precision R. Not copyable or movable (its output
/// refers to its scene).
template <int D, std::floating_point R>
class RunDriver {
 public:
  /// Called after each step, before its output, with the simulation (which it may change, e.g.
  /// perturb) and what the step did.
  using StepObserver = std::function<void(Simulation<D, R>&, const StepInfo&)>;

  /// A new run of `desc`. Everything that can be refused is checked before the directory is
  /// touched (check_fits_in_memory, the simulation's construction); then, with a settings.dir,
  /// prepare_output_directory removes what an earlier run left there. Throws sph::Error.
  RunDriver(SceneDesc desc, RunSettings settings);
  /// The continuation of the run whose checkpoint `checkpoint` holds (`desc` from its scene: see
  /// open_run_to_resume), in settings.dir, which must be that run's directory: checks it
  /// (prepare_resume_directory) and restores the simulation and the output from the checkpoint.
  /// Throws sph::Error.
  RunDriver(SceneDesc desc, CheckpointReader& checkpoint, RunSettings settings);
  ~RunDriver();
  RunDriver(const RunDriver&) = delete;
  RunDriver& operator=(const RunDriver&) = delete;

  const SceneDesc& scene() const { return desc_; }
  const RunSettings& settings() const { return settings_; }
  /// The neighbor mode's name and the thread count, as summary.json records them.
  const RunInfo& info() const { return info_; }
  Simulation<D, R>& simulation() { return sim_; }
  const Simulation<D, R>& simulation() const { return sim_; }
  /// The run's output; null without a directory.
  const RunOutput<D, R>* output() const { return output_.get(); }
  /// Steps done when this session started: 0, or the checkpoint's step.
  std::int64_t first_step() const { return first_step_; }
  /// A resumed run's warning about its restored output ("" if none), e.g. missing stats rows.
  const std::string& resume_warning() const { return resume_warning_; }

  /// Runs `n` steps (at most those left) and nothing else: no output, no callbacks; a warm-up
  /// before a timed stretch. Only for a run without a directory (SPH_CHECK) that has not run
  /// yet. Throws the step's sph::Error.
  void advance(std::int64_t n);
  /// One step and nothing else (no output, no callbacks, no limit at the scene's last step): for
  /// a caller that drives the steps itself, as the Python module does. Only for a run without a
  /// directory (SPH_CHECK) that has not run(). Throws the step's sph::Error (a blow-up, a failed
  /// health check); its warnings are new_warnings() of what it returns.
  const StepInfo& step();
  /// The free surface of the particles now (sph/surface/surface.h), made as `sph run --surface`
  /// makes each frame's: `settings` (resolution, smoothing, iso) fitted to the scene's particle
  /// spacing and cut by its container and its obstacles where they are now. Throws sph::Error
  /// for bad settings (surface_settings_error).
  SurfaceMesh surface(SurfaceSettings settings) const;
  /// The texts of the health warnings a step raised first (HealthMonitor::warning), in the
  /// order of the health kinds: what run() reports through RunCallbacks::warning.
  std::vector<std::string> new_warnings(const StepInfo& step) const;
  /// Runs the steps left, until the scene's last, a stop request or a failure; a new run first
  /// writes its initial output (frame 0, scene.json). Ends the output (summary.json with the
  /// status) and returns how the run ended. A failure of a step, of its output or of a
  /// checkpoint is returned (Failed), not thrown; a failure to write the initial output or the
  /// final summary throws sph::Error. Once per driver (SPH_CHECK).
  RunResult run(const RunCallbacks& callbacks = {}, const StepObserver& on_step = {});

 private:
  SceneDesc desc_;
  RunSettings settings_;
  Simulation<D, R> sim_;
  RunInfo info_;
  std::unique_ptr<RunOutput<D, R>> output_;
  Stopwatch wall_;
  std::int64_t first_step_ = 0;
  std::string resume_warning_;
  bool resumed_ = false, ran_ = false;
  std::size_t surfaces_written_ = 0;  ///< frames whose surface is written (settings_.surface)
  /// Writes the surface of the newest frame if it has none yet (settings_.surface).
  void write_new_surface();
  /// The scene's steps are done, or its end time reached (SceneDesc::end_time).
  bool finished() const;
  /// Tells the simulation where CFL steps must end: the next frame's time, the run's end.
  void set_barrier();
};

extern template class RunDriver<2, float>;
extern template class RunDriver<2, double>;
extern template class RunDriver<3, float>;
extern template class RunDriver<3, double>;

}  // namespace sph
