#include <sph/solver/simulation.h>

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include <sph/core/error.h>
#include <sph/core/kernels.h>
#include <sph/core/parallel.h>
#include <sph/core/simd.h>
#include <sph/core/state_stream.h>
#include <sph/core/timer.h>
#include <sph/solver/gradient_correction.h>
#include <sph/solver/nozzle.h>
#include <sph/solver/smoothing.h>
#include <sph/solver/time_step.h>
#include <sph/solver/wcsph.h>

namespace sph {

namespace {

/// Measures one particle for the health statistics (after its motion): containment, speed,
/// density ratio, and its energy, kinetic + gravity (from the container's lowest point along g)
/// + the wall springs it compresses (the penetrations of WallContact, ks pen^2 / 2 per kg); and,
/// for the initial state only (kInternal), the internal energy of the EOS p = k (rho - rho0),
/// e = k (ln(rho / rho0) + rho0 / rho - 1) >= 0 per kg where the pressure is not clamped.
template <int D, std::floating_point R>
class HealthProbe {
 public:
  HealthProbe(const SimulationParams<D>& p, R w0, std::span<const RigidPose<D>> poses,
              std::span<const std::uint8_t> moving)
      : p_(p),
        poses_(poses),
        moving_(moving),
        tol_(kOutsideTolerance * 2.0 * p.particle_radius),
        r_(p.particle_radius),
        w0_(w0),
        tension_(p.fluid.negative_pressure == NegativePressure::Allow),
        springs_(p.boundary.handling == BoundaryHandling::Penalty) {
    for (int d = 0; d < D; ++d) low_ += std::max(p.gravity[d] * p.container.lo[d], p.gravity[d] * p.container.hi[d]);
  }

  template <bool kInternal>
  void add(detail::HealthChunk& c, std::size_t i, const Vec<D, R>& xr, const Vec<D, R>& vr, R m, R rho) const {
    const Vec<D, double> x = vec_cast<double>(xr), x_world = x;
    const double v2 = static_cast<double>(norm2(vr)), md = static_cast<double>(m);
    double out = -kNoLimit, springs = 0;  // signed distance past the container's planes
    for (int d = 0; d < D; ++d) {
      out = std::max({out, p_.container.lo[d] - x[d], x[d] - p_.container.hi[d]});
      if (springs_)
        springs +=
            squared_positive(p_.container.lo[d] + r_ - x[d]) + squared_positive(x[d] - (p_.container.hi[d] - r_));
    }
    for (std::size_t k = 0; k < p_.obstacles.size(); ++k) {
      const Box<D>& b = p_.obstacles[k];
      // (a moving obstacle: measured in its own frame, where its pose puts the particle)
      const Vec<D, double> x = k < moving_.size() && moving_[k] ? poses_[k].to_rest(x_world) : x_world;
      double in = kNoLimit, grown = kNoLimit;  // depth inside the box, and inside the box grown by r
      if (obstacle_shape(p_, k)) {             // (a shape: its signed distance, exact within r of it)
        const double s = obstacle_distance(p_, k, x, r_).distance;
        in = -s, grown = r_ - s;
      } else {
        for (int d = 0; d < D; ++d) {
          in = std::min({in, x[d] - b.lo[d], b.hi[d] - x[d]});
          grown = std::min({grown, x[d] - (b.lo[d] - r_), (b.hi[d] + r_) - x[d]});
        }
      }
      if (in > tol_) ++c.inside;
      if (in > 0 && in > c.inside_depth) c.inside_depth = in, c.inside_i = i;
      if (springs_) springs += squared_positive(grown);
    }
    const double ratio = static_cast<double>(rho) / p_.fluid.rest_density;
    if constexpr (kInternal)
      if (ratio > 1 || (tension_ && ratio > 0))
        c.internal += md * p_.fluid.stiffness * (std::log(ratio) + 1 / ratio - 1);
    record(c, i, v2, out, ratio, rho > m * w0_,
           md * (0.5 * v2 + (low_ - dot(p_.gravity, x)) + 0.5 * p_.walls.stiffness * springs), md);
  }

  /// add<false> of particles [b, e) in order (positions x, velocities v, densities rho), the
  /// same bits. Without obstacles each batch of kBatch particles is measured lane by lane
  /// (vectorized: the same operations on each particle's values, in the same order), then
  /// recorded one by one (the maxima, the counts, and the sums in particle order); with
  /// obstacles, one add at a time.
  void add_run(detail::HealthChunk& c, std::size_t b, std::size_t e, const Vec<D, R>* x, const Vec<D, R>* v, R m,
               const R* rho) const {
    constexpr std::size_t kBatch = 8;
    std::size_t i = b;
    if (p_.obstacles.empty()) {
      const double md = static_cast<double>(m), ks = 0.5 * p_.walls.stiffness;
      const R with_neighbours = m * w0_;
      using P = simd::Pack<double>;
      static_assert(kBatch == static_cast<std::size_t>(simd::kLanes<double>));
      const P zero = P::set1(0.0);
      for (; i + kBatch <= e; i += kBatch) {
        alignas(64) double xs[D][kBatch], v2[kBatch], out[kBatch], term[kBatch], ratio[kBatch];
        for (std::size_t l = 0; l < kBatch; ++l) {
          for (int d = 0; d < D; ++d) xs[d][l] = static_cast<double>(x[i + l][d]);
          v2[l] = static_cast<double>(norm2(v[i + l]));
          ratio[l] = static_cast<double>(rho[i + l]);
        }
        P o = P::set1(-kNoLimit), springs = zero, g = zero;
        for (int d = 0; d < D; ++d) {
          const P xd = P::load(xs[d]);
          const P below = P::set1(p_.container.lo[d]) - xd, above = xd - P::set1(p_.container.hi[d]);
          o = select(o < below, below, o);  // (std::max's choice: the first of equals)
          o = select(o < above, above, o);
          if (springs_) {
            const P a = P::set1(p_.container.lo[d] + r_) - xd, z = xd - P::set1(p_.container.hi[d] - r_);
            springs = springs + (select(a > zero, a * a, zero) + select(z > zero, z * z, zero));
          }
          g = g + P::set1(p_.gravity[d]) * xd;
        }
        o.store(out);
        (P::load(ratio) / P::set1(p_.fluid.rest_density)).store(ratio);
        (P::set1(md) * (P::set1(0.5) * P::load(v2) + (P::set1(low_) - g) + P::set1(ks) * springs)).store(term);
        for (std::size_t l = 0; l < kBatch; ++l)
          record(c, i + l, v2[l], out[l], ratio[l], rho[i + l] > with_neighbours, term[l], md);
      }
    }
    for (; i < e; ++i) add<false>(c, i, x[i], v[i], m, rho[i]);
  }

 private:
  static double squared_positive(double a) { return a > 0 ? a * a : 0.0; }

  /// Records particle i's measures in c: its speed squared v2, its distance `out` past the
  /// container's planes, its density ratio (counted when it has a neighbour within h) and energy.
  void record(detail::HealthChunk& c, std::size_t i, double v2, double out, double ratio, bool has_neighbours,
              double energy, double md) const {
    if (v2 > c.v2) c.v2 = v2, c.v_i = i;
    if (out > tol_) ++c.outside;
    if (out > 0 && out > c.outside_depth) c.outside_depth = out, c.outside_i = i;
    if (has_neighbours) {  // (a neighbour within h added to its own contribution)
      if (ratio < c.rho_min) c.rho_min = ratio, c.rho_min_i = i;
      if (ratio > c.rho_max) c.rho_max = ratio, c.rho_max_i = i;
    }
    c.energy += energy;
    c.mass += md;
  }

  const SimulationParams<D>& p_;
  std::span<const RigidPose<D>> poses_;
  std::span<const std::uint8_t> moving_;
  double tol_, r_, low_ = 0;
  R w0_;
  bool tension_;
  bool springs_;  // penalty walls: their springs' energy counts
};

}  // namespace

template <int D, std::floating_point R>
Simulation<D, R>::Simulation(SimulationParams<D> params, ParticleSet<D, R> particles)
    : params_(std::move(params)),
      particles_(std::move(particles)),
      boundary_(make_boundary<D, R>(params_)),
      poses_(params_.obstacles.size()),
      health_poses_(params_.obstacles.size()),
      emitters_(params_.emitters.size()),
      monitor_(health_scene(params_), params_.health_failures) {
  // The fluid's particles have the scene's one mass (the emitters' too).
  SPH_CHECK(particles_.empty() || particles_.mass == static_cast<R>(params_.particle_mass),
            "the particles' mass differs from the scene's particle mass");
  particles_.mass = static_cast<R>(params_.particle_mass);
  NeighborOptions& opt = neighbor_options_;
  opt.radius = params_.kernel_radius;
  opt.full_rebuild_period = params_.full_rebuild_period;
  opt.verlet_skin = params_.verlet_skin;
  opt.tracked_skin = params_.tracked_skin;
  // (CFL: the largest step, which sizes the tracked modes' automatic skin generously)
  opt.time_step = cfl() ? std::max(params_.time_step, params_.cfl.max_dt) : params_.time_step;
  SPH_CHECK(params_.reorder_period >= 0, "reorder period must be >= 0");
  if (cfl()) {
    SPH_CHECK(params_.cfl.factor > 0 && params_.cfl.min_dt > 0 && params_.cfl.max_dt >= params_.cfl.min_dt,
              "CFL parameters out of range");
    last_cfl_dt_ = 0.5 * params_.time_step;  // (the first step takes at most timeStepSize)
    // The limits but the acoustic one (which next_time_step() takes with the flow's speed).
    for (const TimeStepLimit& l : time_step_limits(params_))
      if (!l.acoustic) cfl_limit_ = std::min(cfl_limit_, kAutoTimeStepFraction * l.dt_warn);
  }
  if (params_.method == SimulationMethod::Dfsph) {
    if (params_.boundary.handling != BoundaryHandling::Particles)
      throw Error(kDfsphNeedsBoundaryParticles, "Configuration.simulationMethod");
    dfsph_ =
        std::make_unique<DfsphSolver<D, R>>(params_.dfsph, particles_, static_cast<R>(2.0 * params_.particle_radius));
  }
  if (params_.fluid.viscosity_solve == ViscositySolve::Implicit) {
    if (params_.fluid.viscosity_model != ViscosityModel::Paper)
      throw Error(kImplicitViscosityNeedsPaperModel, "Fluid.viscositySolver");
    viscosity_ = std::make_unique<ImplicitViscosity<D, R>>();
  }
  if (any_obstacle_moves(params_)) {
    SPH_CHECK(params_.motions.size() <= params_.obstacles.size() && params_.bodies.size() <= params_.obstacles.size(),
              "one motion and one body per obstacle");
    for (std::size_t k = 0; k < params_.obstacles.size(); ++k) moving_.push_back(obstacle_moves(params_, k) ? 1 : 0);
    init_bodies();
    place_obstacles();
  }
  neighbors_ = make_neighbor_strategy<D, R>(params_.neighbors, opt);
  neighbors_->set_boundary(boundary_.position);
  // Where the strategy builds every list each step (standard), the density sums are made then.
  pair_density_ = make_pair_density<D, R>(static_cast<R>(params_.kernel_radius), params_.fluid);
  if (!neighbors_->visit_pairs_with(pair_density_.get())) pair_density_.reset();
  if (params_.audit) auditor_ = std::make_unique<ListAuditor<D, R>>();
  reserve_for_emitters();
  measure_initial_state();
}

template <int D, std::floating_point R>
void Simulation<D, R>::measure_initial_state() {
  const NeighborOptions& opt = neighbor_options_;
  // Density and pressure of the initial state, so that frame 0 shows real values. Exact lists
  // from a throwaway standard strategy: the run's own strategy starts at step 0.
  if (!particles_.empty()) {
    auto exact = make_neighbor_strategy<D, R>(NeighborMode::Standard, opt);
    exact->set_boundary(boundary_.position);
    exact->update(particles_);
    compute_density_pressure(particles_, exact->lists(), static_cast<R>(params_.kernel_radius), params_.fluid,
                             boundary_view(exact->boundary_lists()));
  }
  // The initial state's energy, the reference of the energy watch (measured as each step is).
  integrate_and_check<false>(R(0));
  // The bound E0 adds the initial internal energy of the EOS (>= 0 at every density), which a
  // start off rest density releases; the steps' energy leaves it out (it is >= 0).
  double energy = 0, mass = 0;
  for (const detail::HealthChunk& c : health_chunks_) energy += c.energy + c.internal, mass += c.mass;
  monitor_.set_initial(energy + body_energy(), mass);
}

template <int D, std::floating_point R>
void Simulation<D, R>::init_bodies() {
  obstacle_body_.assign(params_.obstacles.size(), 0);
  for (std::size_t k = 0; k < params_.obstacles.size(); ++k) {
    const BodyParams<D>& b = obstacle_body(params_, k);
    if (!b.dynamic) continue;
    SPH_CHECK(!obstacle_motion(params_, k).moves(), "a floating body has no prescribed motion");
    SPH_CHECK(body_obstacle_.size() < 65535, "too many floating bodies");
    body_obstacle_.push_back(k);
    obstacle_body_[k] = static_cast<std::uint16_t>(body_obstacle_.size());
    body_mass_.push_back(obstacle_mass_properties(params_, k, b.density));
    bodies_.push_back(initial_body_state(body_mass_.back().center, b));
  }
  if (body_obstacle_.empty()) {
    obstacle_body_.clear();
    return;
  }
  body_force_.assign(bodies_.size(), BodyLoad<D>{});
  contact_rate_ = body_contact_rate(body_contact_step(params_));
  if (boundary_.size() > 0) {
    sample_body_.assign(boundary_.size(), 0);
    for (std::size_t k = 0; k < params_.obstacles.size(); ++k)
      std::fill(sample_body_.begin() + static_cast<std::ptrdiff_t>(boundary_.obstacle_begin[k]),
                sample_body_.begin() + static_cast<std::ptrdiff_t>(boundary_.obstacle_begin[k + 1]), obstacle_body_[k]);
  }
}

template <int D, std::floating_point R>
RigidPose<D> Simulation<D, R>::pose_now(std::size_t k) const {
  if (!obstacle_body_.empty() && obstacle_body_[k] != 0) {
    const std::size_t s = obstacle_body_[k] - 1u;
    return body_pose(bodies_[s], body_mass_[s].center);
  }
  return pose_at(obstacle_motion(params_, k), time());
}

template <int D, std::floating_point R>
std::vector<RigidPose<D>> Simulation<D, R>::obstacle_poses() const {
  std::vector<RigidPose<D>> poses(params_.obstacles.size());
  for (std::size_t k = 0; k < moving_.size(); ++k)
    if (moving_[k]) poses[k] = pose_now(k);
  return poses;
}

template <int D, std::floating_point R>
void Simulation<D, R>::place_obstacles() {
  if (moving_.empty()) return;
  for (std::size_t k = 0; k < moving_.size(); ++k)
    if (moving_[k]) poses_[k] = pose_now(k);
  place_boundary<D, R>(boundary_, params_, poses_);
}

template <int D, std::floating_point R>
void Simulation<D, R>::add_contacts(double dt, std::vector<BodyLoad<D>>& loads) const {
  const std::size_t nb = bodies_.size();
  // Each body against the container, then between bodies (each pair once, in a fixed order) and
  // with the obstacles that do not float (they do not give way), all from the states at the
  // step's start.
  for (std::size_t s = 0; s < nb; ++s) {
    const std::size_t k = body_obstacle_[s];
    add_container_contact(params_.container, params_.obstacles[k], bodies_[s], body_mass_[s], contact_rate_, dt,
                          loads[s], obstacle_shape(params_, k));
  }
  const auto contact_box = [&](std::size_t k) {
    const std::size_t s = obstacle_body_[k];
    return ContactBox<D>{params_.obstacles[k], pose_now(k), s != 0 ? body_mass_[s - 1].mass : 0.0,
                         obstacle_shape(params_, k)};
  };
  for (std::size_t s = 0; s < nb; ++s) {
    const ContactBox<D> a = contact_box(body_obstacle_[s]);
    for (std::size_t t = s + 1; t < nb; ++t)
      add_body_contact(a, contact_box(body_obstacle_[t]), contact_rate_, dt, loads[s], &loads[t]);
    for (std::size_t k = 0; k < params_.obstacles.size(); ++k)
      if (obstacle_body_[k] == 0) add_body_contact<D>(a, contact_box(k), contact_rate_, dt, loads[s], nullptr);
  }
}

template <int D, std::floating_point R>
void Simulation<D, R>::predict_bodies(double dt) {
  // DFSPH's strong coupling: what the step gives each body besides the fluid (gravity, its
  // contacts, the gyroscopic term), for the density solve's prediction.
  if (body_response_.empty()) return;
  std::vector<BodyLoad<D>>& loads = body_loads_;
  loads.assign(bodies_.size(), BodyLoad<D>{});
  add_contacts(dt, loads);
  for (std::size_t s = 0; s < bodies_.size(); ++s) {
    RigidBodyState<D> after = bodies_[s];
    advance_velocities(after, body_mass_[s], loads[s], params_.gravity, dt);
    body_response_[s].velocity_change = after.velocity - bodies_[s].velocity;
    body_response_[s].angular_velocity_change = after.angular_velocity - bodies_[s].angular_velocity;
  }
}

template <int D, std::floating_point R>
void Simulation<D, R>::advance_bodies(double dt) {
  const std::size_t nb = bodies_.size();
  if (nb == 0) return;
  // Per chunk and body: the fluid's momentum change from the body (D values) and its moment
  // about the body's centre of mass (3), summed in blocks of kSumBlock particles and the blocks
  // in order (the same for any thread count).
  constexpr std::size_t kPer = D + 3;
  const std::size_t n = particles_.size();
  const std::size_t chunks = chunk_count<kSumBlock>(n);
  body_partial_.assign(chunks * nb * kPer, 0.0);
  const bool dv = !body_velocity_change_.empty();
  parallel_chunks<kSumBlock>(n, [&](std::size_t c, std::size_t b, std::size_t e) {
    double* out = &body_partial_[c * nb * kPer];
    for (std::size_t i = b; i < e; ++i)
      for (std::size_t s = 0; s < nb; ++s) {
        Vec<D, double> change = vec_cast<double>(body_acceleration_[i * nb + s]) * dt;
        if (dv) change += vec_cast<double>(body_velocity_change_[i * nb + s]);
        if (norm2(change) == 0) continue;
        change *= static_cast<double>(particles_.mass);
        Vec<3, double> moment{};
        add_moment<D>(moment, vec_cast<double>(particles_.position[i]), bodies_[s].position, change);
        double* o = out + s * kPer;
        for (int d = 0; d < D; ++d) o[d] += change[d];
        for (int a = 0; a < 3; ++a) o[D + a] += moment[a];
      }
  });
  std::vector<BodyLoad<D>>& loads = body_loads_;
  loads.assign(nb, BodyLoad<D>{});
  for (std::size_t s = 0; s < nb; ++s) {
    BodyLoad<D>& load = loads[s];  // the body's: minus the fluid's
    for (std::size_t c = 0; c < chunks; ++c) {
      const double* o = &body_partial_[(c * nb + s) * kPer];
      for (int d = 0; d < D; ++d) load.impulse[d] -= o[d];
      for (int a = 0; a < 3; ++a) load.angular_impulse[a] -= o[D + a];
    }
    body_force_[s].impulse = load.impulse * (1.0 / dt);
    body_force_[s].angular_impulse = load.angular_impulse * (1.0 / dt);
  }
  add_contacts(dt, loads);
  for (std::size_t s = 0; s < nb; ++s) {
    const std::size_t k = body_obstacle_[s];
    advance_body(bodies_[s], body_mass_[s], loads[s], params_.gravity, dt);
    const RigidBodyState<D>& b = bodies_[s];
    if (!all_finite(b.position) || !all_finite(b.velocity) || !all_finite(b.angular_velocity))
      throw Error(fmt::format(
          "simulation blew up at step {} (t = {:.6g} s): the floating body Obstacles[{}] has a position or velocity "
          "that is not finite (the fluid's force on it: {:.6g} N). Lower Configuration.timeStepSize (or "
          "cflMaxTimeStepSize), or make the body denser",
          steps_ + 1, time() + dt, k, std::sqrt(norm2(body_force_[s].impulse))));  // (the step under way)
  }
}

template <int D, std::floating_point R>
void Simulation<D, R>::flag_near_moving_obstacles(double dt) {
  const std::span<std::uint8_t> flags = neighbors_->pair_exit_flags();
  if (moving_.empty() || flags.empty()) return;
  const double h = params_.kernel_radius;
  for (std::size_t k = 0; k < moving_.size(); ++k) {
    if (!moving_[k]) continue;
    const Box<D>& box = params_.obstacles[k];
    const RigidPose<D>& pose = poses_[k];
    const double reach = h + pose_surface_speed<D>(pose, box.lo, box.hi) * dt;
    parallel_for(particles_.size(), [&](std::size_t i) {
      // The distance from the particle to the solid, in its frame.
      const Vec<D, double> X = pose.to_rest(vec_cast<double>(particles_.position[i]));
      if (obstacle_distance(params_, k, X, reach).distance < reach) flags[i] = 1;
    });
  }
}

template <int D, std::floating_point R>
BoundaryView<D, R> Simulation<D, R>::boundary_view(const NeighborLists& lists) const {
  BoundaryView<D, R> v;
  if (boundary_.size() == 0) return v;
  v.position = boundary_.position;
  v.psi = boundary_.psi;
  v.velocity = boundary_.velocity;
  v.lists = &lists;
  v.friction = static_cast<R>(params_.boundary.friction);
  v.extrapolate = params_.boundary.pressure == BoundaryPressure::Extrapolate;
  v.sample_pressure = params_.boundary.pressure != BoundaryPressure::None;
  v.clamp = params_.fluid.negative_pressure == NegativePressure::Clamp;
  v.extrapolation = vec_cast<R>(params_.gravity);
  return v;
}

template <int D, std::floating_point R>
void Simulation<D, R>::reserve_for_emitters() {
  std::int64_t capacity = static_cast<std::int64_t>(particles_.size());
  for (std::size_t k = 0; k < params_.emitters.size(); ++k)
    capacity += params_.emitters[k].max_particles - (k < emitters_.size() ? emitters_[k].emitted : 0);
  particles_.reserve(static_cast<std::size_t>(capacity));
}

template <int D, std::floating_point R>
std::size_t Simulation<D, R>::emit() {
  std::size_t added = 0;
  const double t = time();
  for (std::size_t k = 0; k < params_.emitters.size(); ++k) {
    const EmitterParams<D>& e = params_.emitters[k];
    EmitterState& s = emitters_[k];
    // One layer, emitted `late` seconds after its batch's time: where it has flown since then
    // (x + v late + g late^2 / 2, at v + g late), so that layers keep their spacing whatever
    // the steps.
    const auto add_layer = [&](double late) {
      const std::pair<Vec<D, double>, Vec<D, double>> axes = nozzle_axes<D>(e.direction);
      const int rows = D == 3 ? e.height : 1;
      const Vec<D, double> v0 = e.direction * e.speed;
      const Vec<D, double> flown = late > 0 ? v0 * late + params_.gravity * (0.5 * late * late) : Vec<D, double>{};
      const Vec<D, R> vel = vec_cast<R>(late > 0 ? v0 + params_.gravity * late : v0);
      for (int b = 0; b < rows && s.emitted < e.max_particles; ++b)
        for (int a = 0; a < e.width && s.emitted < e.max_particles; ++a) {
          const Vec<D, double> x = nozzle_position<D>(e, axes.first, axes.second, a, b);
          particles_.add(vec_cast<R>(late > 0 ? x + flown : x), vel);
          ++s.emitted;
          ++added;
        }
    };
    if (cfl()) {
      // Batches every emitEveryNSteps * timeStepSize seconds from the start time, up to the end
      // time: each batch due by this step's start, placed where its layer has flown since its
      // time (a step longer than the period emits several). Steps never shorten for a batch.
      const double period = e.every_steps * params_.time_step;
      if (s.next_time < 0) s.next_time = e.start_time;
      while (s.emitted < e.max_particles && s.next_time <= e.end_time && t + 1e-9 * period >= s.next_time) {
        add_layer(t - s.next_time);
        s.next_time += period;
      }
      continue;
    }
    if (s.emitted >= e.max_particles || t > e.end_time) continue;
    if (s.next_step < 0) {
      if (t + 0.5 * params_.time_step < e.start_time) continue;
      s.next_step = steps_;
    }
    if (steps_ != s.next_step) continue;
    s.next_step += e.every_steps;
    add_layer(0);
  }
  return added;
}

template <int D, std::floating_point R>
double Simulation<D, R>::next_time_step() const {
  if (!cfl()) return params_.time_step;
  const CflParams& c = params_.cfl;
  // The fastest particle, with what the last step's acceleration adds in a step.
  const std::size_t n = particles_.size();
  const double last = last_cfl_dt_;
  partial_.assign(chunk_count(n), 0.0);
  parallel_chunks(n, [&](std::size_t k, std::size_t b, std::size_t e) {
    double m = 0;
    for (std::size_t i = b; i < e; ++i)
      m = std::max(m, std::sqrt(static_cast<double>(norm2(particles_.velocity[i]))) +
                          last * std::sqrt(static_cast<double>(norm2(particles_.acceleration[i]))));
    partial_[k] = m;
  });
  double u = 0;
  for (double p : partial_) u = std::max(u, p);
  // A moving obstacle's surface counts as a particle at its speed (it is about to push the fluid).
  for (std::size_t k = 0; k < moving_.size(); ++k)
    if (moving_[k])
      u = std::max(u, pose_surface_speed<D>(pose_now(k), params_.obstacles[k].lo, params_.obstacles[k].hi));
  // Advective CFL: a particle moves at most 0.4 factor diameters (SPlisHSPlasH's rule).
  double dt = u > 0 ? c.factor * 0.4 * (2.0 * params_.particle_radius) / u : kNoLimit;
  // The scene's other limits (time_step.h's warning levels, as "auto" takes them: cfl_limit_),
  // and the acoustic one with the flow's speed added to the sound's.
  dt = std::min(dt, cfl_limit_);
  const double c0 = std::sqrt(std::max(params_.fluid.stiffness, 0.0));
  if (params_.method == SimulationMethod::Wcsph && c0 + u > 0)
    dt = std::min(dt, kAutoTimeStepFraction * 0.4 * params_.kernel_radius / (c0 + u));
  // DFSPH: the pressure solve says whether the last step was too long (SPlisHSPlasH's
  // iteration-controlled CFL): one that did not converge halves the step, one that took more
  // than half its iteration limit shortens it by 10 %, one that took more than a quarter holds
  // it; the others let it grow by 20 % (WCSPH: by 100 %).
  double growth = 2.0;
  if (dfsph_ && steps_ > 0) {
    const SolveStats& d = last_density_solve_;
    const int most = params_.dfsph.max_iterations;
    growth = !d.converged ? 0.5 : 2 * d.iterations > most ? 0.9 : 4 * d.iterations > most ? 1.0 : 1.2;
  }
  dt = std::min({dt, c.max_dt, growth * last});
  return std::max(dt, c.min_dt);
}

template <int D, std::floating_point R>
typename Simulation<D, R>::StepTime Simulation<D, R>::choose_time_step() const {
  StepTime st;
  st.dt = st.cfl_dt = next_time_step();
  if (!cfl()) return st;
  // The nearest barrier ahead: the caller's (frames, the end). (Emitter batches are not: the
  // next step's emit() places a batch that fell inside this one where its layer has flown.)
  double end = barrier_;
  // Keyframes: a step ends on the next key, where the obstacle's velocity jumps (the step's
  // length took the speed at its start).
  for (std::size_t k = 0; k < moving_.size(); ++k)
    for (const MotionKey<D>& key : obstacle_motion(params_, k).keys)
      if (key.time > time_) {
        end = std::min(end, key.time);
        break;
      }
  const double left = end - time_;
  if (!(left > 0) || !std::isfinite(left)) return st;
  if (left <= st.dt * (1 + 1e-9)) {
    st.dt = left, st.end = end, st.lands = true;
  } else if (left < 2.0 * st.dt) {
    st.dt = 0.5 * left;  // two equal steps rather than a full one and a sliver
  }
  return st;
}

template <int D, std::floating_point R>
void Simulation<D, R>::balance_threads(const NeighborLists* lists) {
  if (lists == nullptr || num_threads() < 2) {
    clear_balance();
    return;
  }
  // A particle's work in a step: its pairs (fluid and boundary, each visited by the density and
  // the force pass) and what it costs without any (kParticleWork pairs' worth: the integration,
  // the walls, the loops' own overhead).
  constexpr std::uint64_t kParticleWork = 8;
  const std::size_t n = particles_.size();
  chunk_work_.assign(chunk_count(n), 0);
  for (std::size_t c = 0; c < chunk_work_.size(); ++c)
    chunk_work_[c] = kParticleWork * (std::min(n, (c + 1) * kChunkSize) - c * kChunkSize);
  lists->add_chunk_entries(chunk_work_);
  if (neighbors_->boundary_lists().particle_count() == n) neighbors_->boundary_lists().add_chunk_entries(chunk_work_);
  balance_loops(n, chunk_work_);
}

template <int D, std::floating_point R>
const StepInfo& Simulation<D, R>::step() {
  StepInfo info;
  info.step = steps_;

  const R h = static_cast<R>(params_.kernel_radius);
  double reorder_seconds = 0;
  if (params_.reorder_period > 0 && steps_ % params_.reorder_period == 0 && particles_.size() > 1) {
    Stopwatch reorder;
    // The lists refer to the old indices: invalidated first, so that the fluid grid, whose memory
    // the sort borrows for its keys and permutations (16 bytes a particle less at the peak, with
    // the grid's coordinates in float 3D), is built again before anything reads it, even if the
    // sort throws.
    neighbors_->invalidate();
    UniformGrid<D, R>* grid = neighbors_->fluid_grid();
    particles_.permute(
        morton_.compute(particles_.position, h, grid ? &grid->lend_scratch(particles_.size()) : nullptr));
    info.reordered = true;
    reorder_seconds = reorder.lap();
  }
  // Emit after reordering, so that this step's new particles are the last ones (callers, like
  // sph compare's perturbation, rely on that).
  info.emitted = emit();
  // Moving obstacles: where they are at the step's start; their samples' lists are all rebuilt.
  place_obstacles();
  if (boundary_.moving()) neighbors_->move_boundary(boundary_.position);
  neighbors_->set_time(time());
  if (pair_density_) pair_density_->aim(particles_);
  neighbors_->update(particles_);
  info.neighbors = neighbors_->counters();
  if (boundary_.moving()) {  // (for strategies that rebuild lists on their own schedule)
    Stopwatch refresh;
    if (neighbors_->refresh_moved_boundary(particles_)) {
      info.neighbors.lists_seconds += refresh.lap();
      info.neighbors.boundary_pairs_stored = neighbors_->boundary_lists().entry_count();
    }
  }
  info.seconds.grid = info.neighbors.grid_seconds + reorder_seconds;
  info.seconds.lists = info.neighbors.lists_seconds;
  // verlet_clusters: the passes run on cluster pairs, and the per-particle lists are built only
  // for what needs them (their build counted with the lists').
  const ClusterPairs<D, R>* clusters = neighbors_->cluster_pairs();
  const bool per_particle =
      !clusters || dfsph_ || viscosity_ || params_.fluid.gradient_correction == GradientCorrection::Renormalize;
  Stopwatch asked;
  const NeighborLists& lists = per_particle ? neighbors_->lists() : no_lists_;
  info.seconds.lists += asked.lap();
  balance_threads(per_particle ? &lists : nullptr);
  BoundaryView<D, R> solid = boundary_view(neighbors_->boundary_lists());
  if (!bodies_.empty()) {  // (what each floating body gives each particle in this step)
    const std::size_t entries = particles_.size() * bodies_.size();
    body_acceleration_.assign(entries, Vec<D, R>{});
    body_velocity_change_.assign(dfsph_ ? entries : 0, Vec<D, R>{});
    solid.body = sample_body_;
    solid.bodies = bodies_.size();
    solid.body_acceleration = body_acceleration_.data();
    solid.body_velocity_change = dfsph_ ? body_velocity_change_.data() : nullptr;
    if (dfsph_) {
      body_response_.resize(bodies_.size());
      for (std::size_t k = 0; k < bodies_.size(); ++k)
        body_response_[k] = {1.0 / body_mass_[k].mass, world_inverse_inertia(bodies_[k], body_mass_[k]),
                             bodies_[k].position};
      solid.body_response = body_response_;
    }
  }
  if (auditor_) {
    info.audited = true;
    info.audit = clusters ? auditor_->audit_clusters(particles_.position, *clusters, h)
                          : auditor_->audit(particles_.position, lists, h);
    info.boundary_audit =
        auditor_->audit_boundary(particles_.position, boundary_.position, neighbors_->boundary_lists(), h);
  }

  Stopwatch watch;
  // (DFSPH: the EOS pressure this pass computes is replaced by the density solve's)
  info.density_in_lists = pair_density_ != nullptr;
  info.pairs_within_h =
      compute_density_pressure(particles_, lists, h, params_.fluid, solid, clusters, info.density_in_lists);
  const R rho0 = static_cast<R>(params_.fluid.rest_density);
  if (dfsph_) {
    const SmoothingKernels<D, R> kernels(params_.fluid, h);
    std::span<const R> correction;
    if (params_.fluid.gradient_correction == GradientCorrection::Renormalize) {
      gradient_corrections(particles_, lists, kernels, solid, rho0, gradient_correction_);
      correction = gradient_correction_;
    }
    dfsph_->compute_factors(particles_, lists, kernels, solid, correction);
    info.seconds.density = watch.lap();
    // (its velocity change does not depend on dt: the last step's is as good as any)
    if (params_.dfsph.divergence_solver)
      info.divergence_solve =
          dfsph_->divergence_solve(particles_, rho0, static_cast<R>(cfl() ? last_cfl_dt_ : params_.time_step));
    info.seconds.solve = watch.lap();
  } else {
    info.seconds.density = watch.lap();
  }
  const StepTime st = choose_time_step();
  const R dt = static_cast<R>(st.dt);
  info.dt = st.dt;
  // The paper's Section 6: particles near a moving body rebuild their lists next step, whatever
  // Eq. 7 predicts (the body's push is not in its linear prediction).
  if (params_.neighbors == NeighborMode::Adaptive && params_.flag_near_moving) flag_near_moving_obstacles(st.dt);
  predict_bodies(static_cast<double>(dt));  // (the dt the bodies advance by)
  const WallContact<D, R> walls(params_.container, params_.obstacles, static_cast<R>(params_.particle_radius),
                                params_.walls, params_.boundary.handling == BoundaryHandling::Penalty, poses_, moving_,
                                obstacle_body_, params_.shapes);
  compute_accelerations(particles_, lists, h, params_.fluid, vec_cast<R>(params_.gravity), walls,
                        neighbors_->pair_exit_flags(), dt, solid, neighbors_->pair_exit_radius(), !dfsph_, clusters,
                        clusters ? nullptr : neighbors_->scratch_until_update());
  info.seconds.forces = watch.lap();
  // The viscosity backward in time, after every other acceleration of the step (DFSPH's density
  // solve then sees the velocities it leaves).
  if (viscosity_) {
    info.viscosity_solve = viscosity_->solve(particles_, lists, h, params_.fluid, dt);
    info.seconds.solve += watch.lap();
  }
  if (dfsph_) {
    info.density_solve = last_density_solve_ = dfsph_->density_solve(particles_, rho0, dt);
    info.seconds.solve += watch.lap();
  }
  // The floating bodies take the fluid's reaction (at the particles' positions before they move).
  advance_bodies(static_cast<double>(dt));  // (the fluid's own dt, rounded as it moves with it)
  ++steps_;                                 // counted even if the checks below throw (as before the passes were fused)
  if (cfl()) {
    time_ = st.lands ? st.end : time_ + st.dt;
    last_cfl_dt_ = st.cfl_dt;
  }
  info.health = integrate_and_check<true>(dt);  // (a blow-up throws here: the step has no record)
  info.time = time();
  info.particles = particles_.size();
  info_ = info;  // the step's record before it is judged: a run writes a failing step's stats row too
  monitor_.check(info_.health, steps_, time(), particles_.size());  // (step k: stats.csv's row k)
  info_.seconds.integrate = watch.lap();
  return info_;
}

template <int D, std::floating_point R>
template <bool kIntegrate>
HealthStats Simulation<D, R>::integrate_and_check(R dt) {
  // Symplectic Euler (v += dt a; x += dt v), the blow-up check and the health statistics in one pass.
  const std::size_t n = particles_.size();
  // (the particles are measured after their motion: the obstacles where they are then)
  for (std::size_t k = 0; k < moving_.size(); ++k)
    if (moving_[k]) health_poses_[k] = pose_now(k);
  const HealthProbe<D, R> probe(
      params_, SmoothingKernels<D, R>(params_.fluid.kernel, static_cast<R>(params_.kernel_radius)).w_zero(),
      health_poses_, moving_);
  health_chunks_.assign(chunk_count(n), detail::HealthChunk{});
  parallel_chunks(n, [&](std::size_t c, std::size_t b, std::size_t e) {
    // (measured into a chunk of the thread's own, stored once: the shared array's entries, read
    // and written for every particle, cost the 1M bench's integration 15 % of its time)
    detail::HealthChunk chunk;
    bool any = false;
    for (std::size_t i = b; i < e; ++i) {
      if constexpr (kIntegrate) {
        particles_.velocity[i] += particles_.acceleration[i] * dt;
        particles_.position[i] += particles_.velocity[i] * dt;
      }
      const auto& x = particles_.position[i];
      const auto& v = particles_.velocity[i];
      any = any || !all_finite(x) || !all_finite(v);
      if constexpr (!kIntegrate) probe.template add<true>(chunk, i, x, v, particles_.mass, particles_.density[i]);
    }
    if constexpr (kIntegrate)
      probe.add_run(chunk, b, e, particles_.position.data(), particles_.velocity.data(), particles_.mass,
                    particles_.density.data());
    chunk.bad = any;
    health_chunks_[c] = chunk;
  });
  // Name the first bad particle in index order (a deterministic message).
  for (std::size_t c = 0; kIntegrate && c < health_chunks_.size(); ++c) {
    if (!health_chunks_[c].bad) continue;
    for (std::size_t i = c * kChunkSize; i < std::min(n, (c + 1) * kChunkSize); ++i) {
      const auto& x = particles_.position[i];
      const auto& v = particles_.velocity[i];
      if (all_finite(x) && all_finite(v)) continue;
      throw Error(
          fmt::format("simulation blew up at step {} (t = {:.6g} s): particle id {}: {} is not finite; density "
                      "{:.6g}, pressure {:.6g}. Lower Configuration.timeStepSize or raise Fluid.viscosity",
                      steps_, time(), particles_.id[i], all_finite(x) ? "velocity" : "position",
                      static_cast<double>(particles_.density[i]), static_cast<double>(particles_.pressure[i])));
    }
  }
  HealthStats s = reduce_health();
  s.energy += body_energy();
  // The floating bodies' deepest corner past a container wall (the first body's in ties).
  static constexpr const char* kWalls[3][2] = {{"-x", "+x"}, {"-y", "+y"}, {"-z", "+z"}};
  for (std::size_t b = 0; b < bodies_.size(); ++b) {
    const std::size_t k = body_obstacle_[b];
    const WallDepth w =
        container_depth(params_.container, params_.obstacles[k], bodies_[b], body_mass_[b], obstacle_shape(params_, k));
    if (w.depth > s.body_depth)
      s.body_depth = w.depth, s.body_obstacle = static_cast<std::int64_t>(k),
      s.body_wall = kWalls[w.axis][w.high ? 1 : 0];
  }
  return s;
}

template <int D, std::floating_point R>
double Simulation<D, R>::body_energy() const {
  double e = 0, low = 0;  // (gravity's zero where the particles' is: the container's lowest point along g)
  for (int d = 0; d < D; ++d)
    low += std::max(params_.gravity[d] * params_.container.lo[d], params_.gravity[d] * params_.container.hi[d]);
  for (std::size_t s = 0; s < bodies_.size(); ++s) {
    const RigidBodyState<D>& b = bodies_[s];
    const MassProperties<D>& mp = body_mass_[s];
    // Kinetic (w . I_w w, in the body's frame), gravity's, and the container contact's springs.
    const std::array<double, 9> r = principal_frame(b, mp);
    double spin = 0;
    for (int a = 0; a < 3; ++a) {
      double w = 0;  // (R^T w)_a
      for (int c = 0; c < 3; ++c) w += r[static_cast<std::size_t>(3 * c + a)] * b.angular_velocity[c];
      spin += mp.inertia[a] * w * w;
    }
    e += 0.5 * mp.mass * norm2(b.velocity) + 0.5 * spin + mp.mass * (low - dot(params_.gravity, b.position));
    const std::size_t k = body_obstacle_[s];
    e += container_contact_energy(params_.container, params_.obstacles[k], b, mp, contact_rate_,
                                  obstacle_shape(params_, k));
  }
  return e;
}

template <int D, std::floating_point R>
HealthStats Simulation<D, R>::reduce_health() const {
  detail::HealthChunk all;
  const auto better = [](double a, std::size_t ia, double b, std::size_t ib, bool larger) {
    return ia != detail::HealthChunk::kNone && (ib == detail::HealthChunk::kNone || (larger ? a > b : a < b));
  };
  for (const detail::HealthChunk& c : health_chunks_) {  // chunk order; ties keep the lower index
    all.outside += c.outside, all.inside += c.inside, all.energy += c.energy;
    if (better(c.outside_depth, c.outside_i, all.outside_depth, all.outside_i, true))
      all.outside_depth = c.outside_depth, all.outside_i = c.outside_i;
    if (better(c.inside_depth, c.inside_i, all.inside_depth, all.inside_i, true))
      all.inside_depth = c.inside_depth, all.inside_i = c.inside_i;
    if (better(c.v2, c.v_i, all.v2, all.v_i, true)) all.v2 = c.v2, all.v_i = c.v_i;
    if (better(c.rho_min, c.rho_min_i, all.rho_min, all.rho_min_i, false))
      all.rho_min = c.rho_min, all.rho_min_i = c.rho_min_i;
    if (better(c.rho_max, c.rho_max_i, all.rho_max, all.rho_max_i, true))
      all.rho_max = c.rho_max, all.rho_max_i = c.rho_max_i;
  }
  const auto speed = [&](std::size_t i) { return std::sqrt(static_cast<double>(norm2(particles_.velocity[i]))); };
  HealthStats s;
  s.outside = all.outside, s.inside_solid = all.inside, s.energy = all.energy;
  if (all.outside_i != detail::HealthChunk::kNone)
    s.outside_depth = all.outside_depth, s.outside_id = particles_.id[all.outside_i],
    s.outside_speed = speed(all.outside_i);
  if (all.inside_i != detail::HealthChunk::kNone)
    s.inside_depth = all.inside_depth, s.inside_id = particles_.id[all.inside_i], s.inside_speed = speed(all.inside_i);
  const double c0 = std::sqrt(std::max(params_.fluid.stiffness, 0.0));
  if (all.v_i != detail::HealthChunk::kNone) {
    s.max_mach = c0 > 0 ? std::sqrt(all.v2) / c0 : (all.v2 > 0 ? kNoLimit : 0.0);
    s.mach_id = particles_.id[all.v_i];
  }
  if (all.rho_min_i != detail::HealthChunk::kNone) s.rho_min = all.rho_min;
  if (all.rho_max_i != detail::HealthChunk::kNone) s.rho_max = all.rho_max, s.rho_max_id = particles_.id[all.rho_max_i];
  return s;
}

template <int D, std::floating_point R>
double Simulation<D, R>::kinetic_energy() const {
  return kinetic_energy_and_max_speed().first;
}

template <int D, std::floating_point R>
double Simulation<D, R>::max_speed() const {
  return kinetic_energy_and_max_speed().second;
}

template <int D, std::floating_point R>
std::pair<double, double> Simulation<D, R>::kinetic_energy_and_max_speed() const {
  // chunked_sum's blocks and order for the energy, and each block's largest |v|^2 beside (a max is
  // exact: the same for any thread count).
  const std::size_t n = particles_.size(), blocks = chunk_count<kSumBlock>(n);
  partial_.assign(2 * blocks, 0.0);
  parallel_chunks<kSumBlock>(n, [&](std::size_t c, std::size_t b, std::size_t e) {
    double s = 0;
    R m = 0;
    for (std::size_t i = b; i < e; ++i) {
      const R v2 = norm2(particles_.velocity[i]);
      s += 0.5 * static_cast<double>(particles_.mass) * static_cast<double>(v2);
      m = std::max(m, v2);
    }
    partial_[c] = s;
    partial_[blocks + c] = static_cast<double>(m);
  });
  double energy = 0, fastest = 0;
  for (std::size_t c = 0; c < blocks; ++c) energy += partial_[c];
  for (std::size_t c = 0; c < blocks; ++c) fastest = std::max(fastest, partial_[blocks + c]);
  return {energy, std::sqrt(fastest)};
}

template <int D, std::floating_point R>
Vec<D, double> Simulation<D, R>::momentum() const {
  Vec<D, double> p{};
  for (int d = 0; d < D; ++d)
    p[d] = chunked_sum(particles_.size(), partial_, [&](std::size_t i) {
      return static_cast<double>(particles_.mass) * static_cast<double>(particles_.velocity[i][d]);
    });
  return p;
}

template <int D, std::floating_point R>
void Simulation<D, R>::perturb_positions(std::size_t first, double amplitude, std::uint64_t seed) {
  for (std::size_t i = first; i < particles_.size(); ++i) {
    // SplitMix64 on (seed, id): a fixed sequence per particle, independent of its index.
    std::uint64_t state = seed ^ (particles_.id[i] * 0x9E3779B97F4A7C15ull);
    const auto next = [&state] {
      std::uint64_t z = (state += 0x9E3779B97F4A7C15ull);
      z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
      z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
      return static_cast<double>((z ^ (z >> 31)) >> 11) * 0x1.0p-53 * 2.0 - 1.0;  // [-1, 1)
    };
    Vec<D, double> dir{};
    double len2 = 0;
    do {
      for (int d = 0; d < D; ++d) dir[d] = next();
      len2 = norm2(dir);
    } while (len2 > 1.0 || len2 < 1e-6);
    dir *= amplitude / std::sqrt(len2);
    particles_.position[i] += vec_cast<R>(dir);
  }
}

template <int D, std::floating_point R>
void Simulation<D, R>::save_state(StateWriter& out) const {
  out.put(static_cast<std::uint8_t>(params_.neighbors));
  out.put(steps_);
  out.put(time_);
  out.put(last_cfl_dt_);
  out.put(last_density_solve_.iterations);
  out.put(last_density_solve_.error);
  out.put(static_cast<std::uint8_t>(last_density_solve_.converged));
  out.put(emitters_);
  out.put(bodies_);
  particles_.save(out);
  neighbors_->save_state(out);
  monitor_.save_state(out);
}

template <int D, std::floating_point R>
void Simulation<D, R>::load_state(StateReader& in) {
  in.expect(in.get<std::uint8_t>() == static_cast<std::uint8_t>(params_.neighbors), "written in another neighbor mode");
  in.get(steps_);
  in.expect(steps_ >= 0, "a negative step count");
  in.get(time_);
  in.get(last_cfl_dt_);
  in.expect(std::isfinite(time_) && time_ >= 0 && std::isfinite(last_cfl_dt_) && last_cfl_dt_ >= 0,
            "a bad time or time step");
  in.get(last_density_solve_.iterations);
  in.get(last_density_solve_.error);
  last_density_solve_.converged = in.get<std::uint8_t>() != 0;
  in.expect(last_density_solve_.iterations >= 0, "a negative iteration count");
  in.get(emitters_);
  in.expect(emitters_.size() == params_.emitters.size(), "a different number of emitters");
  for (std::size_t k = 0; k < emitters_.size(); ++k)
    in.expect(emitters_[k].emitted >= 0 && emitters_[k].emitted <= params_.emitters[k].max_particles,
              "an emitter's count out of range");
  const std::size_t body_count = bodies_.size();
  in.get(bodies_);
  in.expect(bodies_.size() == body_count, "a different number of floating bodies");
  for (const RigidBodyState<D>& b : bodies_) {
    const auto& q = b.orientation;
    in.expect(all_finite(b.position) && all_finite(b.velocity) && all_finite(b.angular_velocity) &&
                  std::abs(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3] - 1) < 1e-9,
              "a floating body's state is not finite, or its orientation not a unit quaternion");
  }
  particles_.load(in);
  neighbors_->load_state(in, particles_.size());
  monitor_.load_state(in);
  reserve_for_emitters();
  info_ = StepInfo{};
}

template class Simulation<2, float>;
template class Simulation<2, double>;
template class Simulation<3, float>;
template class Simulation<3, double>;

}  // namespace sph
