#include <sph/run/driver.h>

#include <fmt/format.h>

#include <sph/core/error.h>
#include <sph/core/parallel.h>
#include <sph/io/atomic_file.h>
#include <sph/run/memory.h>
#include <sph/scene/builders.h>
#include <sph/surface/solid_cut.h>

namespace sph {

std::string_view to_string(RunStatus status) {
  switch (status) {
    case RunStatus::Completed:
      return "completed";
    case RunStatus::Interrupted:
      return "interrupted";
    case RunStatus::Failed:
      return "failed";
  }
  return "unknown";
}

namespace {

/// The simulation of `desc`, once the scene is known to fit in memory; its particles keep their
/// initial positions if something may read them (RunSettings::every_field).
template <int D, std::floating_point R>
Simulation<D, R> build_simulation(const SceneDesc& desc, const RunSettings& settings) {
  check_fits_in_memory(desc);
  const bool initial = settings.every_field || (!settings.dir.empty() &&
                                                desc.output.frames_hold(kParticleFields[field::kInitialPosition].name));
  return make_simulation<D, R>(desc, initial);
}

/// `s` fitted to the scene's particle spacing and cut by its container (fit_to_run).
template <int D>
void fit_to_scene(SurfaceSettings& s, const SimulationParams<D>& p) {
  std::array<double, 3> lo{}, hi{};
  for (int d = 0; d < D; ++d) lo[d] = p.container.lo[d], hi[d] = p.container.hi[d];
  fit_to_run(s, p.particle_radius, lo, hi);
}

}  // namespace

template <int D, std::floating_point R>
RunDriver<D, R>::RunDriver(SceneDesc desc, RunSettings settings)
    : desc_(std::move(desc)),
      settings_(std::move(settings)),
      sim_(build_simulation<D, R>(desc_, settings_)),
      info_{std::string(to_string(sim_.params().neighbors)), num_threads()} {
  SPH_CHECK(settings_.checkpoint_every == 0 || !settings_.dir.empty(), "RunDriver: checkpoints need a directory");
  SPH_CHECK(!settings_.surface || !settings_.dir.empty(), "RunDriver: surfaces need a directory");
  if (settings_.surface) {
    SurfaceSettings& s = settings_.surface->settings;
    fit_to_scene(s, sim_.params());
    if (const std::string e = surface_settings_error(s); !e.empty()) throw Error(e, "--surface");
  }
  if (!settings_.dir.empty()) {
    prepare_output_directory(settings_.dir);
    output_ = std::make_unique<RunOutput<D, R>>(settings_.dir, desc_, info_);
  }
  wall_ = Stopwatch();
}

template <int D, std::floating_point R>
RunDriver<D, R>::RunDriver(SceneDesc desc, CheckpointReader& checkpoint, RunSettings settings)
    : desc_(std::move(desc)),
      settings_(std::move(settings)),
      sim_(build_simulation<D, R>(desc_, settings_)),
      info_{std::string(to_string(sim_.params().neighbors)), num_threads()},
      resumed_(true) {
  SPH_CHECK(!settings_.dir.empty(), "RunDriver: a resumed run needs its directory");
  prepare_resume_directory(settings_.dir);
  output_ = std::make_unique<RunOutput<D, R>>(settings_.dir, desc_, info_, checkpoint.header().identity.run_id);
  wall_ = Stopwatch();
  resume_warning_ = checkpoint.restore(sim_, *output_);
  first_step_ = sim_.steps_done();
}

template <int D, std::floating_point R>
RunDriver<D, R>::~RunDriver() = default;

template <int D, std::floating_point R>
void RunDriver<D, R>::write_new_surface() {
  if (!settings_.surface || !output_ || output_->frames_written() == surfaces_written_) return;
  const std::size_t index = output_->frames_written() - 1;
  const SurfaceMesh mesh = surface(settings_.surface->settings);
  const std::filesystem::path dir = settings_.dir / "surface";
  make_writable_directory(dir, "the surfaces");
  write_surface_frame(dir, index, mesh, sim_.time(), settings_.surface->formats);
  surfaces_written_ = output_->frames_written();
}

template <int D, std::floating_point R>
SurfaceMesh RunDriver<D, R>::surface(SurfaceSettings settings) const {
  fit_to_scene(settings, sim_.params());
  settings.solids = obstacles_distance(sim_.params(), sim_.obstacle_poses());  // (where they are now)
  const ParticleSet<D, R>& ps = sim_.particles();
  std::vector<double> xyz(3 * ps.size(), 0.0);
  parallel_for(ps.size(), [&](std::size_t i) {
    for (int d = 0; d < D; ++d) xyz[3 * i + static_cast<std::size_t>(d)] = static_cast<double>(ps.position[i][d]);
  });
  return extract_surface(xyz, D, settings);
}

template <int D, std::floating_point R>
void RunDriver<D, R>::advance(std::int64_t n) {
  SPH_CHECK(!output_ && !ran_, "RunDriver::advance: only before run() of a run that writes nothing");
  for (std::int64_t k = 0; k < n && !finished(); ++k) {
    set_barrier();
    sim_.step();
  }
}

template <int D, std::floating_point R>
const StepInfo& RunDriver<D, R>::step() {
  SPH_CHECK(!output_ && !ran_, "RunDriver::step: only for a run that writes nothing, outside run()");
  set_barrier();
  return sim_.step();
}

template <int D, std::floating_point R>
bool RunDriver<D, R>::finished() const {
  // A run to an end time ends there, however many steps it took: steps that end on a frame's
  // time are shorter than the rule's (a relative 1e-12: a time that lands on the end by a
  // barrier is the end). desc_.steps is then an estimate (the progress bar's).
  if (desc_.end_time > 0) return sim_.time() >= desc_.end_time * (1 - 1e-12);
  return sim_.steps_done() >= desc_.steps;
}

template <int D, std::floating_point R>
void RunDriver<D, R>::set_barrier() {
  // CFL steps end on the next frame's time and on the run's end (fixed steps ignore it).
  double barrier = desc_.end_time > 0 ? desc_.end_time : kNoLimit;
  if (output_) barrier = std::min(barrier, output_->next_frame_time());
  sim_.set_time_barrier(barrier);
}

template <int D, std::floating_point R>
std::vector<std::string> RunDriver<D, R>::new_warnings(const StepInfo& step) const {
  std::vector<std::string> texts;
  for (std::size_t k = 0; k < kHealthKinds; ++k)
    if ((step.health.new_warnings >> k & 1u) != 0) texts.push_back(sim_.health().warning(static_cast<HealthKind>(k)));
  return texts;
}

template <int D, std::floating_point R>
RunResult RunDriver<D, R>::run(const RunCallbacks& callbacks, const StepObserver& on_step) {
  SPH_CHECK(!ran_, "RunDriver::run: a driver runs once");
  ran_ = true;
  RunResult result;
  result.first_step = first_step_;
  const auto end = [&](RunStatus status, std::string message) {
    result.status = status;
    result.message = std::move(message);
    result.steps_done = sim_.steps_done();
    result.warnings = sim_.health().warnings();
    result.wall_seconds = wall_.elapsed();
    if (output_) output_->finish(sim_, result.message, result.wall_seconds);
    return result;
  };
  const std::int64_t steps = desc_.steps;
  if (output_ && !resumed_) output_->begin(sim_);  // (a failure here is thrown: nothing has run)
  if (output_) {
    surfaces_written_ = resumed_ ? output_->frames_written() : 0;  // a resumed run's earlier frames have theirs
    write_new_surface();
  }
  // The steps whose stats rows are written. A step that fails its health checks (or a --strict
  // one that warns) gets its row too, so that the message's step is stats.csv's last row; one
  // that blew up (no finite state to measure) has none.
  std::int64_t rows = sim_.steps_done();
  const auto failing_step_row = [&] {
    if (!output_ || rows == sim_.steps_done() || sim_.last_step().step + 1 != sim_.steps_done()) return;
    rows = sim_.steps_done();
    try {
      output_->after_step(sim_, sim_.last_step(), false);
    } catch (const Error&) {  // (the failure being reported says more than a full disk's)
    }
  };
  try {
    while (!finished()) {
      set_barrier();
      const StepInfo& step = sim_.step();
      const bool last = finished();
      if (step.health.new_warnings != 0) {
        for (const std::string& w : new_warnings(step)) {
          if (settings_.strict) {  // (the failure's message is the warning: it is told once)
            failing_step_row();
            result.error = w + " (--strict)";
            return end(RunStatus::Failed, "failed: " + result.error);
          }
          if (callbacks.warning) callbacks.warning(w);
        }
      }
      if (on_step) on_step(sim_, step);
      if (output_) {
        rows = sim_.steps_done();
        output_->after_step(sim_, step, last);
        write_new_surface();
      }
      if (callbacks.progress) callbacks.progress(sim_.steps_done(), step.particles);
      if (callbacks.stop_requested && !last) {
        if (std::string cause = callbacks.stop_requested(sim_.steps_done()); !cause.empty()) {
          if (output_)
            write_checkpoint(settings_.dir, desc_, sim_, *output_, wall_.elapsed(), settings_.checkpoint_every);
          result.stop_cause = cause;
          return end(RunStatus::Interrupted,
                     desc_.end_time > 0
                         ? fmt::format("interrupted by {} after step {} (t = {:.6g} s of {:.6g} s)", cause,
                                       sim_.steps_done(), sim_.time(), desc_.end_time)
                         : fmt::format("interrupted by {} after step {} of {}", cause, sim_.steps_done(), steps));
        }
      }
      // A resumed run also checkpoints its last step, so that its checkpoint is never behind its end.
      if ((settings_.checkpoint_every > 0 && (sim_.steps_done() % settings_.checkpoint_every == 0 || last)) ||
          (resumed_ && last))
        write_checkpoint(settings_.dir, desc_, sim_, *output_, wall_.elapsed(), settings_.checkpoint_every);
    }
  } catch (const Error& e) {
    failing_step_row();
    result.error = e.what();
    return end(RunStatus::Failed, std::string("failed: ") + e.what());
  }
  const std::vector<std::string> warnings = sim_.health().warnings();
  if (warnings.empty()) return end(RunStatus::Completed, "completed");
  std::string message = "completed with warnings: ";
  for (std::size_t k = 0; k < warnings.size(); ++k) message += (k ? "; " : "") + warnings[k];
  return end(RunStatus::Completed, message);
}

template class RunDriver<2, float>;
template class RunDriver<2, double>;
template class RunDriver<3, float>;
template class RunDriver<3, double>;

}  // namespace sph
