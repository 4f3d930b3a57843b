#include <sph/solver/simulation.h>

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include <sph/core/error.h>
#include <sph/core/parallel.h>
#include <sph/core/state_stream.h>
#include <sph/core/timer.h>
#include <sph/solver/nozzle.h>
#include <sph/solver/wcsph.h>

namespace sph {

namespace {

/// Deterministic sum over particles: fixed chunks, partial sums added in chunk order.
template <class F>
double chunked_sum(std::size_t n, std::vector<double>& partial, F&& term) {
  partial.assign(chunk_count(n), 0.0);
  parallel_chunks(n, [&](std::size_t c, std::size_t b, std::size_t e) {
    double s = 0;
    for (std::size_t i = b; i < e; ++i) s += term(i);
    partial[c] = s;
  });
  double s = 0;
  for (double p : partial) s += p;
  return s;
}

}  // namespace

template <int D, std::floating_point R>
Simulation<D, R>::Simulation(SimulationParams<D> params, ParticleSet<D, R> particles)
    : params_(std::move(params)), particles_(std::move(particles)), emitters_(params_.emitters.size()) {
  NeighborOptions opt;
  opt.radius = params_.kernel_radius;
  opt.full_rebuild_period = params_.full_rebuild_period;
  opt.verlet_skin = params_.verlet_skin;
  SPH_CHECK(params_.reorder_period >= 0, "reorder period must be >= 0");
  neighbors_ = make_neighbor_strategy<D, R>(params_.neighbors, opt);
  if (params_.audit) auditor_ = std::make_unique<ListAuditor<D, R>>();
  double extent = 0;
  for (int d = 0; d < D; ++d) extent = std::max(extent, params_.container.hi[d] - params_.container.lo[d]);
  speed_limit_ = 20.0 * std::sqrt(params_.fluid.stiffness) + std::sqrt(2.0 * norm(params_.gravity) * extent);
  reserve_for_emitters();
  // Density and pressure of the initial state, so that frame 0 shows real values. Exact lists
  // from a throwaway standard strategy: the run's own strategy starts at step 0.
  if (!particles_.empty()) {
    auto exact = make_neighbor_strategy<D, R>(NeighborMode::Standard, opt);
    exact->update(particles_);
    compute_density_pressure(particles_, exact->lists(), static_cast<R>(params_.kernel_radius), params_.fluid);
  }
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
    if (s.emitted >= e.max_particles || t > e.end_time) continue;
    if (s.next_step < 0) {
      if (t + 0.5 * params_.time_step < e.start_time) continue;
      s.next_step = steps_;
    }
    if (steps_ != s.next_step) continue;
    s.next_step += e.every_steps;
    const auto [u, w] = nozzle_axes<D>(e.direction);
    const int rows = D == 3 ? e.height : 1;
    const Vec<D, R> vel = vec_cast<R>(e.direction * e.speed);
    for (int b = 0; b < rows && s.emitted < e.max_particles; ++b)
      for (int a = 0; a < e.width && s.emitted < e.max_particles; ++a) {
        particles_.add(vec_cast<R>(nozzle_position<D>(e, u, w, a, b)), vel, static_cast<R>(params_.particle_mass));
        ++s.emitted;
        ++added;
      }
  }
  return added;
}

template <int D, std::floating_point R>
const StepInfo& Simulation<D, R>::step() {
  StepInfo info;
  info.step = steps_;

  const R dt = static_cast<R>(params_.time_step);
  const R h = static_cast<R>(params_.kernel_radius);
  double reorder_seconds = 0;
  if (params_.reorder_period > 0 && steps_ % params_.reorder_period == 0 && particles_.size() > 1) {
    Stopwatch reorder;
    morton_.compute(particles_.position, h, perm_);
    particles_.permute(perm_);
    neighbors_->invalidate();
    info.reordered = true;
    reorder_seconds = reorder.lap();
  }
  // Emit after reordering, so that this step's new particles are the last ones (callers, like
  // sph compare's perturbation, rely on that).
  info.emitted = emit();
  neighbors_->update(particles_);
  info.neighbors = neighbors_->counters();
  info.seconds.grid = info.neighbors.grid_seconds + reorder_seconds;
  info.seconds.lists = info.neighbors.lists_seconds;
  const NeighborLists& lists = neighbors_->lists();
  if (auditor_) {
    info.audited = true;
    info.audit = auditor_->audit(particles_.position, lists, h);
  }

  Stopwatch watch;
  info.pairs_within_h = compute_density_pressure(particles_, lists, h, params_.fluid);
  info.seconds.density = watch.lap();
  const WallContact<D, R> walls(params_.container, params_.obstacles, static_cast<R>(params_.particle_radius),
                                params_.walls);
  compute_accelerations(particles_, lists, h, params_.fluid, vec_cast<R>(params_.gravity), walls,
                        neighbors_->pair_exit_flags(), dt);
  info.seconds.forces = watch.lap();
  ++steps_;  // counted even if the check below throws (as before the passes were fused)
  integrate_and_check(dt);
  info.seconds.integrate = watch.lap();

  info.time = time();
  info.particles = particles_.size();
  info_ = info;
  return info_;
}

template <int D, std::floating_point R>
void Simulation<D, R>::integrate_and_check(R dt) {
  // Symplectic Euler (v += dt a; x += dt v) and the blow-up check in one pass.
  const std::size_t n = particles_.size();
  const double limit2 = speed_limit_ * speed_limit_;
  std::vector<std::uint8_t>& bad = bad_;
  bad.assign(chunk_count(n), 0);
  parallel_chunks(n, [&](std::size_t c, std::size_t b, std::size_t e) {
    bool any = false;
    for (std::size_t i = b; i < e; ++i) {
      particles_.velocity[i] += particles_.acceleration[i] * dt;
      particles_.position[i] += particles_.velocity[i] * dt;
      any = any || !all_finite(particles_.position[i]) || !all_finite(particles_.velocity[i]) ||
            static_cast<double>(norm2(particles_.velocity[i])) > limit2;
    }
    bad[c] = any ? 1 : 0;
  });
  // Name the first bad particle in index order (a deterministic message).
  for (std::size_t c = 0; c < bad.size(); ++c) {
    if (!bad[c]) continue;
    for (std::size_t i = c * kChunkSize; i < std::min(n, (c + 1) * kChunkSize); ++i) {
      const auto& x = particles_.position[i];
      const auto& v = particles_.velocity[i];
      std::string what;
      if (!all_finite(x))
        what = "position is not finite";
      else if (!all_finite(v))
        what = "velocity is not finite";
      else if (static_cast<double>(norm2(v)) > limit2)
        what = fmt::format("speed {:.4g} m/s exceeds the blow-up limit {:.4g} m/s", static_cast<double>(norm(v)),
                           speed_limit_);
      else
        continue;
      throw Error(
          fmt::format("simulation blew up at step {} (t = {:.6g} s): particle id {}: {}; density {:.6g}, "
                      "pressure {:.6g}. Lower Configuration.timeStepSize or raise Fluid.viscosity",
                      steps_ - 1, time(), particles_.id[i], what, static_cast<double>(particles_.density[i]),
                      static_cast<double>(particles_.pressure[i])));
    }
  }
}

template <int D, std::floating_point R>
double Simulation<D, R>::kinetic_energy() const {
  return chunked_sum(particles_.size(), partial_, [&](std::size_t i) {
    return 0.5 * static_cast<double>(particles_.mass[i]) * static_cast<double>(norm2(particles_.velocity[i]));
  });
}

template <int D, std::floating_point R>
double Simulation<D, R>::max_speed() const {
  // Per-chunk maxima (a max is exact: the same for any thread count).
  const std::size_t n = particles_.size();
  partial_.assign(chunk_count(n), 0.0);
  parallel_chunks(n, [&](std::size_t c, std::size_t b, std::size_t e) {
    R m = 0;
    for (std::size_t i = b; i < e; ++i) m = std::max(m, norm2(particles_.velocity[i]));
    partial_[c] = static_cast<double>(m);
  });
  double m = 0;
  for (double p : partial_) m = std::max(m, p);
  return std::sqrt(m);
}

template <int D, std::floating_point R>
Vec<D, double> Simulation<D, R>::momentum() const {
  Vec<D, double> p{};
  for (int d = 0; d < D; ++d)
    p[d] = chunked_sum(particles_.size(), partial_, [&](std::size_t i) {
      return static_cast<double>(particles_.mass[i]) * static_cast<double>(particles_.velocity[i][d]);
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
  out.put(emitters_);
  particles_.save(out);
  neighbors_->save_state(out);
}

template <int D, std::floating_point R>
void Simulation<D, R>::load_state(StateReader& in) {
  in.expect(in.get<std::uint8_t>() == static_cast<std::uint8_t>(params_.neighbors), "written in another neighbor mode");
  in.get(steps_);
  in.expect(steps_ >= 0, "a negative step count");
  in.get(emitters_);
  in.expect(emitters_.size() == params_.emitters.size(), "a different number of emitters");
  for (std::size_t k = 0; k < emitters_.size(); ++k)
    in.expect(emitters_[k].emitted >= 0 && emitters_[k].emitted <= params_.emitters[k].max_particles,
              "an emitter's count out of range");
  particles_.load(in);
  neighbors_->load_state(in, particles_.size());
  reserve_for_emitters();
  info_ = StepInfo{};
}

template class Simulation<2, float>;
template class Simulation<2, double>;
template class Simulation<3, float>;
template class Simulation<3, double>;

}  // namespace sph
