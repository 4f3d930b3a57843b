#pragma once
/// \file Simulation<D,R>: one WCSPH run (paper Algorithm 1, or 2 through the neighbor policy).

#include <memory>
#include <span>
#include <utility>
#include <vector>

#include <sph/core/particle_set.h>
#include <sph/neighbors/audit.h>
#include <sph/neighbors/reorder.h>
#include <sph/neighbors/strategy.h>
#include <sph/solver/boundary.h>
#include <sph/solver/dfsph.h>
#include <sph/solver/health.h>
#include <sph/solver/params.h>
#include <sph/solver/rigid_body.h>
#include <sph/solver/viscosity.h>
#include <sph/solver/wcsph.h>

namespace sph {

/// Wall seconds spent in each phase of one step.
struct PhaseTimes {
  double grid = 0, lists = 0, density = 0, forces = 0, integrate = 0;
  double solve = 0;  ///< DFSPH's pressure solves (0 with WCSPH)
  double total() const { return grid + lists + density + forces + integrate + solve; }
  PhaseTimes& operator+=(const PhaseTimes& o) {
    grid += o.grid, lists += o.lists, density += o.density, forces += o.forces, integrate += o.integrate;
    solve += o.solve;
    return *this;
  }
};

/// What one step did.
struct StepInfo {
  std::int64_t step = 0;  ///< index of the step just taken (0-based)
  double time = 0;        ///< simulated time after the step, s
  double dt = 0;          ///< the step's time step, s
  std::size_t particles = 0;
  std::size_t emitted = 0;  ///< particles added by emitters at the start of this step
  bool reordered = false;   ///< particles were reordered in memory (Morton curve) this step
  NeighborCounters neighbors;
  std::uint64_t pairs_within_h = 0;  ///< listed (directed) pairs closer than h this step
  /// The fluid pairs' density sums were made while the lists were built (standard mode,
  /// PairDensity): their time is in seconds.lists, and seconds.density holds the rest of the pass.
  bool density_in_lists = false;
  bool audited = false;         ///< SimulationParams::audit was on: `audit` is filled
  ListAudit audit;              ///< pairs within h that the lists missed this step
  ListAudit boundary_audit;     ///< fluid-boundary pairs within h the boundary lists missed
  PhaseTimes seconds;           ///< (the audit's own time is in none of the phases)
  HealthStats health;           ///< measured in the integrate pass, judged by the health monitor
  SolveStats density_solve;     ///< DFSPH: the constant-density solve (0 iterations with WCSPH)
  SolveStats divergence_solve;  ///< DFSPH: the divergence solve
  SolveStats viscosity_solve;   ///< Fluid.viscositySolver "implicit": the viscosity solve
};

namespace detail {
/// One chunk's share of the health statistics (indices into the particle arrays; kNone: none).
struct HealthChunk {
  static constexpr std::size_t kNone = ~std::size_t{0};
  std::uint64_t outside = 0, inside = 0;
  double outside_depth = 0, inside_depth = 0, v2 = -1, rho_min = kNoLimit, rho_max = -kNoLimit;
  double energy = 0, internal = 0, mass = 0;
  std::size_t outside_i = kNone, inside_i = kNone, v_i = kNone, rho_min_i = kNone, rho_max_i = kNone;
  bool bad = false;  // a non-finite position or velocity
};
}  // namespace detail

/// Progress of one emitter (part of the simulation state).
struct EmitterState {
  std::int64_t emitted = 0;
  std::int64_t next_step = -1;  ///< step of the next batch; -1 before start time (fixed time step)
  /// TimeStepping::Cfl: time of the next batch, s (-1 before the first); batches come every
  /// emitEveryNSteps * timeStepSize seconds, and steps end on their times
  double next_time = -1;
};

/// A running simulation. Each step():
///   1. every reorder_period steps the particles are reordered in memory along a Morton curve
///      (ids are kept) and every list is rebuilt; then emitters add their batch (if due), at
///      the end of the particle arrays,
///   2. the neighbor strategy updates the lists (grid + lists phases),
///   3. density and pressure (Eq. 4, EOS),
///   4. pressure, viscous, gravity and wall accelerations (Eq. 5, 6; penalty springs or the
///      boundary particles' terms), with the Eq. 7 test if the strategy asks for it (the force
///      pass gathers every neighbor's velocity anyway),
///   5. symplectic Euler integration, then a check that every value is finite; the same pass
///      measures the health statistics (StepInfo::health), which the health monitor judges.
/// With TimeStepping::Cfl each step chooses its time step (next_time_step(), shortened to end on
/// a barrier) before the force pass, whose Eq. 7 test predicts with it.
template <int D, std::floating_point R>
class Simulation {
 public:
  /// Takes the initial particles; throws sph::Error if the neighbor mode is unavailable.
  Simulation(SimulationParams<D> params, ParticleSet<D, R> particles);

  /// Advances one time step. Throws sph::Error if a particle's state becomes non-finite
  /// ("simulation blew up") or the health monitor fails the step (supersonic, fluid lost
  /// through the walls, collapsed, energy gained: see kHealthWatches), naming the step, the
  /// time, the particle id, the quantity and what to change. Warnings the step raised are in
  /// StepInfo::health.new_warnings (their text in health()).
  const StepInfo& step();
  /// The health monitor: the warnings given so far, their counts, the extremes seen.
  const HealthMonitor& health() const { return monitor_; }

  const ParticleSet<D, R>& particles() const { return particles_; }
  /// The particles, to change between steps (the Python module: its setters, and handing the
  /// arrays its views show to those views). The number of particles must not change. After a
  /// change of positions or velocities call particles_moved(); a field given a new buffer with
  /// the same values needs nothing.
  ParticleSet<D, R>& edit_particles() { return particles_; }
  /// The positions or velocities were changed between steps: the next step rebuilds every
  /// neighbor list (the strategy's own state, such as the adaptive flags and the verlet
  /// reference positions, starts again from those lists), and the state is measured again as at
  /// the start (densities, pressures, and the energy the health monitor's energy watch compares
  /// with: a state given by hand is where the run now starts from).
  void particles_moved() {
    neighbors_->invalidate();
    measure_initial_state();
  }
  const SimulationParams<D>& params() const { return params_; }
  const NeighborStrategy<D, R>& neighbors() const { return *neighbors_; }
  /// The boundary particles (empty with penalty walls).
  const BoundarySet<D, R>& boundary() const { return boundary_; }
  std::int64_t steps_done() const { return steps_; }
  /// Simulated time, s: steps times the time step (fixed), or the sum of the steps' (CFL).
  double time() const { return cfl() ? time_ : static_cast<double>(steps_) * params_.time_step; }
  /// The next steps end no later than `t` (s): the step that would pass it is shortened to end
  /// on it exactly (TimeStepping::Cfl; a fixed step is never changed). The run driver sets the
  /// next frame's time and the end of the run.
  void set_time_barrier(double t) { barrier_ = t; }
  /// The time step the next step would take (without barriers), s.
  double next_time_step() const;
  const StepInfo& last_step() const { return info_; }
  const std::vector<EmitterState>& emitter_states() const { return emitters_; }

  /// Every obstacle's pose now (motion.h): a prescribed motion's at time(), a floating body's from
  /// its state, the identity for one at rest.
  std::vector<RigidPose<D>> obstacle_poses() const;
  /// The floating bodies (Obstacles[].dynamic), in the obstacles' order: body s is obstacle
  /// body_obstacles()[s]; its state now, its mass properties, and what the fluid gave it in the
  /// last step as a mean force, N, and moment about its centre of mass, N m (2D: per metre).
  const std::vector<std::size_t>& body_obstacles() const { return body_obstacle_; }
  const std::vector<RigidBodyState<D>>& bodies() const { return bodies_; }
  const std::vector<MassProperties<D>>& body_masses() const { return body_mass_; }
  /// DFSPH's strong coupling: each floating body's response of the last step (BoundaryView::
  /// body_response; empty with WCSPH).
  std::span<const typename BoundaryView<D, R>::BodyResponse> body_responses() const { return body_response_; }
  const std::vector<BodyLoad<D>>& body_fluid_forces() const { return body_force_; }

  /// Total kinetic energy, J (J/m in 2D). Deterministic for any thread count. (This and the
  /// other reductions use a shared scratch buffer: do not call them concurrently.)
  double kinetic_energy() const;
  /// Largest particle speed, m/s.
  double max_speed() const;
  /// kinetic_energy() and max_speed() in one parallel pass: what a step's stats row takes.
  std::pair<double, double> kinetic_energy_and_max_speed() const;
  /// Total linear momentum, kg m/s. Deterministic for any thread count.
  Vec<D, double> momentum() const;

  /// Displaces the particles of index >= `first` by a pseudo-random vector of length
  /// `amplitude` (m) each, drawn from the particle's id and `seed` only (so the same particle
  /// gets the same displacement whatever its index). Used to measure how fast two runs that
  /// differ by round-off drift apart (the chaos floor of `sph compare`).
  void perturb_positions(std::size_t first, double amplitude, std::uint64_t seed);

  /// Writes the complete state for a checkpoint: steps done, every particle field and id,
  /// emitter progress, the neighbor strategy's state (lists and flags) and the health monitor's. There is no random
  /// state: nothing in a step draws random numbers.
  void save_state(StateWriter& out) const;
  /// Replaces the state with what save_state() wrote (by a simulation of the same scene and
  /// mode): the following steps are bitwise identical to those of the simulation that wrote
  /// it. Throws sph::Error if the data does not fit this simulation.
  void load_state(StateReader& in);

 private:
  NeighborOptions neighbor_options_;  ///< the lists' radius, skins and step, set at construction
  bool cfl() const { return params_.time_stepping == TimeStepping::Cfl; }
  /// A step's time step: dt (shortened by a barrier), the CFL step before that, and whether the
  /// step ends on the barrier `end` (the time is then set to it exactly).
  struct StepTime {
    double dt = 0, cfl_dt = 0, end = 0;
    bool lands = false;
  };
  /// The step's time step: fixed, or CFL with the barriers (frames, emitters, the end).
  StepTime choose_time_step() const;
  std::size_t emit();
  void reserve_for_emitters();
  /// Places the moving obstacles (their poses, and their boundary samples) at the current time.
  void place_obstacles();
  // Splits the step's loops between the threads by the pairs each chunk of particles holds
  // (balance_loops), or evenly when the passes run on cluster pairs (lists == nullptr).
  void balance_threads(const NeighborLists* lists);
  /// Obstacle k's pose now (obstacle_poses()).
  RigidPose<D> pose_now(std::size_t k) const;
  /// Sets up the floating bodies (constructor).
  void init_bodies();
  /// The state's densities and pressures from exact lists, and its energy as the energy watch's
  /// reference (the start of a run, or a state set by hand: particles_moved).
  void measure_initial_state();
  /// The fluid's reaction on each body over a step of dt (from body_acceleration_ and
  /// body_velocity_change_, at the particles' positions before they move), plus the container's
  /// contact and the contacts between bodies and with the other obstacles; then each body takes
  /// its step.
  void advance_bodies(double dt);
  /// Adds each floating body's contact impulses over dt (the container, the other bodies, the
  /// obstacles that do not float) to loads[s], from the states at the step's start.
  void add_contacts(double dt, std::vector<BodyLoad<D>>& loads) const;
  /// DFSPH's strong coupling: sets body_response_'s velocity changes of the step but the fluid's.
  void predict_bodies(double dt);
  /// Adaptive mode (SimulationParams::flag_near_moving): flags for a list rebuild every particle
  /// within h plus its travel in a step of dt of a moving obstacle.
  void flag_near_moving_obstacles(double dt);
  /// What the passes see of the boundary particles, with `lists` as their lists.
  BoundaryView<D, R> boundary_view(const NeighborLists& lists) const;
  /// Integrates (symplectic Euler; none with kIntegrate false), checks every value (throws on a
  /// blow-up) and measures the health statistics, in one pass.
  template <bool kIntegrate>
  HealthStats integrate_and_check(R dt);
  /// Folds the per-chunk statistics (in chunk order: the same for any thread count).
  HealthStats reduce_health() const;
  /// The floating bodies' energy, J (J/m in 2D): kinetic (translation and rotation), gravity's
  /// (from the container's lowest point along g, as the particles'), and the container contact's
  /// springs. Part of the health monitor's energy.
  double body_energy() const;

  SimulationParams<D> params_;
  ParticleSet<D, R> particles_;
  BoundarySet<D, R> boundary_;
  std::vector<std::uint8_t> moving_;        // per obstacle: whether it moves (empty: none does)
  std::vector<RigidPose<D>> poses_;         // per obstacle: its pose at the current step's start
  std::vector<RigidPose<D>> health_poses_;  // per obstacle: its pose at the step's end (the health checks)
  // Floating bodies: body s is obstacle body_obstacle_[s]; obstacle_body_[k] is s + 1 (0: none);
  // sample_body_[b] the same for boundary sample b (empty without boundary particles).
  std::vector<std::size_t> body_obstacle_;
  std::vector<std::uint16_t> obstacle_body_, sample_body_;
  std::vector<RigidBodyState<D>> bodies_;
  std::vector<MassProperties<D>> body_mass_;
  std::vector<typename BoundaryView<D, R>::BodyResponse> body_response_;  // DFSPH's strong coupling
  std::vector<BodyLoad<D>> body_force_;  // the last step's fluid force and moment on each body
  std::vector<BodyLoad<D>> body_loads_;  // each body's impulses in the step (kept: no allocation per step)
  double contact_rate_ = 0;              // body_contact_rate() of the run's longest step, 1/s
  // What each body gave each particle in the step (BoundaryView::body_acceleration, ...).
  std::vector<Vec<D, R>> body_acceleration_, body_velocity_change_;
  std::vector<double> body_partial_;  // per-chunk sums of the bodies' loads
  std::unique_ptr<NeighborStrategy<D, R>> neighbors_;
  std::unique_ptr<PairDensity<D, R>> pair_density_;  // the density sums the strategy's builds make (null: none)
  std::unique_ptr<ListAuditor<D, R>> auditor_;
  MortonOrder<D, R> morton_;
  mutable std::vector<double> partial_;             // per-chunk partial sums (kept: no allocation per step)
  std::vector<detail::HealthChunk> health_chunks_;  // per-chunk health statistics (kept)
  std::vector<EmitterState> emitters_;
  std::int64_t steps_ = 0;
  double time_ = 0;         // TimeStepping::Cfl: simulated time, s
  double last_cfl_dt_ = 0;  // the last step's CFL step before barriers shortened it (its growth limit), s
  double barrier_ = kNoLimit;
  double cfl_limit_ = kNoLimit;                         // TimeStepping::Cfl: the scene's limits but the acoustic one, s
  std::unique_ptr<DfsphSolver<D, R>> dfsph_;            // SimulationMethod::Dfsph
  std::vector<R> gradient_correction_;                  // DFSPH with GradientCorrection::Renormalize: L
  std::vector<std::uint64_t> chunk_work_;               // each chunk's pairs, for balance_threads
  NeighborLists no_lists_;                              // the lists the passes get when they run on cluster pairs
  std::unique_ptr<ImplicitViscosity<D, R>> viscosity_;  // ViscositySolve::Implicit
  SolveStats last_density_solve_;                       // its last constant-density solve (the CFL step's feedback)
  HealthMonitor monitor_;
  StepInfo info_;
};

extern template class Simulation<2, float>;
extern template class Simulation<2, double>;
extern template class Simulation<3, float>;
extern template class Simulation<3, double>;

}  // namespace sph
