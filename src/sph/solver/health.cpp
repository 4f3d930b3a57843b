#include <sph/solver/health.h>

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include <sph/core/error.h>
#include <sph/solver/rigid_body.h>

namespace sph {

namespace {

const HealthWatch& watch(HealthKind kind) { return kHealthWatches[static_cast<std::size_t>(kind)]; }

/// Monaghan's artificial viscosity alpha = 0.1 as a dynamic viscosity, by the formula the scene
/// reader's default viscosity uses (viscosity_for_sound_speed, solver/params.h).
double suggested_viscosity(const HealthScene& s) {
  return viscosity_for_sound_speed(s.dimension, kArtificialViscosityAlpha, s.kernel_radius, s.sound_speed,
                                   s.rest_density);
}

/// The setting that shortens the steps, with its value: "Configuration.timeStepSize (now 0.0001
/// s)", or under CFL steps "Configuration.cflFactor (now 0.5) or cflMaxTimeStepSize (now 0.005 s)".
/// `lower`: with a value half as large suggested ("e.g. to ...").
std::string step_setting(const HealthScene& s, bool lower = false) {
  const double now = s.cfl ? s.cfl_factor : s.time_step;
  const char* unit = s.cfl ? "" : " s";
  std::string value = fmt::format("now {:.3g}{}", now, unit);
  if (lower) value += fmt::format(", e.g. to {:.3g}{}", 0.5 * now, unit);
  return s.cfl ? fmt::format("Configuration.cflFactor ({}) or cflMaxTimeStepSize (now {:.3g} s)", value, s.time_step)
               : fmt::format("Configuration.timeStepSize ({})", value);
}

/// What walls that hold a particle need: stiffness for the speed v within r and for the head,
/// critical damping, and the step the springs allow.
std::string wall_advice(const HealthScene& s, double v) {
  if (s.boundary_particles)
    return fmt::format(
        "boundary particles hold a particle that sees them within h = {:.3g} m; at the run's top speed v = {:.3g} "
        "m/s a step of {:.3g} s moves it {:.2g} h: take smaller steps, lower {}{}",
        s.kernel_radius, v, s.time_step, v * s.time_step / s.kernel_radius, step_setting(s),
        s.misses_pairs ? ", or a neighbor mode that never misses a pair (standard, verlet, tracked, adaptive_exact): "
                         "the adaptive mode's lists miss the pairs a particle comes to (fluid pairs, and the boundary "
                         "samples of solids at rest)"
                       : "");
  const double r = s.particle_radius;
  const double ks_speed = (v / r) * (v / r);
  const double ks_head = s.gravity * s.head / (2.0 * r * r);
  const double ks = std::max(ks_speed, ks_head);
  return fmt::format(
      "walls that stop a particle at the run's top speed v = {:.3g} m/s within r = {:.3g} m need "
      "Container.wallStiffness >= (v / r)^2 = {:.3g}, and >= g H / (2 r^2) = {:.3g} for the head H = {:.3g} m "
      "(now {:.3g}), with Container.wallDamping about 2 sqrt(wallStiffness) = {:.3g} (now {:.3g}) and "
      "Configuration.{} <= 0.5 / sqrt(wallStiffness) = {:.3g} s (now {:.3g} s)",
      v, r, ks_speed, ks_head, s.head, s.wall_stiffness, 2.0 * std::sqrt(ks), s.wall_damping,
      s.cfl ? "cflMaxTimeStepSize" : "timeStepSize", 0.5 / std::sqrt(std::max(ks, s.wall_stiffness)), s.time_step);
}

std::string speed_advice(const HealthScene& s, double v) {
  return fmt::format(
      "Fluid.stiffness >= (10 v)^2 = {:.3g} (now {:.3g}) keeps it at Mach 0.1; or slow the flow with "
      "Fluid.viscosity (now {:.3g}; Monaghan's alpha = 0.1 is about {:.3g})",
      100.0 * v * v, s.stiffness, s.viscosity, suggested_viscosity(s));
}

}  // namespace

template <int D>
HealthScene health_scene(const SimulationParams<D>& p) {
  HealthScene s;
  s.dimension = D;
  s.sound_speed = std::sqrt(std::max(p.fluid.stiffness, 0.0));
  s.kernel_radius = p.kernel_radius;
  s.particle_radius = p.particle_radius;
  s.rest_density = p.fluid.rest_density;
  s.stiffness = p.fluid.stiffness;
  s.viscosity = p.fluid.viscosity;
  s.wall_stiffness = p.walls.stiffness;
  s.wall_damping = p.walls.damping;
  s.time_step = p.time_step;
  s.gravity = norm(p.gravity);
  if (s.gravity > 0) {
    double head = 0;  // the container's extent along g
    for (int d = 0; d < D; ++d) head += std::abs(p.gravity[d]) * (p.container.hi[d] - p.container.lo[d]);
    s.head = head / s.gravity;
  }
  // (an obstacle on a prescribed motion does work on the fluid; a floating body's energy is counted
  // with the fluid's)
  s.closed = p.emitters.empty() &&
             std::none_of(p.motions.begin(), p.motions.end(), [](const ObstacleMotion<D>& m) { return m.moves(); });
  s.tension = p.fluid.negative_pressure == NegativePressure::Allow;
  s.incompressible = p.method == SimulationMethod::Dfsph;
  s.boundary_particles = p.boundary.handling == BoundaryHandling::Particles;
  s.misses_pairs = p.neighbors == NeighborMode::Adaptive;
  s.implicit_viscosity = p.fluid.viscosity_solve == ViscositySolve::Implicit;
  if (p.time_stepping == TimeStepping::Cfl) {
    s.cfl = true;
    s.cfl_factor = p.cfl.factor;
    s.time_step = p.cfl.max_dt;
  }
  s.contact_step = any_dynamic_body(p) ? body_contact_step(p) : 0.0;
  return s;
}

template HealthScene health_scene<2>(const SimulationParams<2>&);
template HealthScene health_scene<3>(const SimulationParams<3>&);

HealthMonitor::HealthMonitor(const HealthScene& scene, bool fail) : scene_(scene), fail_(fail) {}

double HealthMonitor::energy_scale() const {
  return std::abs(initial_energy_) + total_mass_ * scene_.sound_speed * scene_.sound_speed / 2e4;
}

void HealthMonitor::warn(HealthStats& stats, HealthKind kind, std::string message) {
  const auto k = static_cast<std::size_t>(kind);
  ++counts_[k];
  if (order_[k] != 0) return;
  order_[k] = ++raised_;
  messages_[k] = std::move(message);
  stats.new_warnings |= 1u << k;
}

void HealthMonitor::check(HealthStats& st, std::int64_t step, double time, std::size_t particles) {
  const HealthScene& s = scene_;
  const double n = static_cast<double>(std::max<std::size_t>(particles, 1));
  const double h = s.kernel_radius;
  const double top_speed = st.max_mach * s.sound_speed;
  max_mach_ = std::max(max_mach_, st.max_mach);
  rho_max_ = std::max(rho_max_, st.rho_max);
  rho_min_ = std::min(rho_min_, st.rho_min);
  max_energy_ = std::max(max_energy_, st.energy);
  // Messages are made only when a threshold is crossed: a healthy step allocates nothing.
  const auto at = [&] { return fmt::format("at step {} (t = {:.6g} s)", step, time); };
  const auto fail = [&](const std::string& what) {
    if (fail_) throw Error(what);
  };

  // Supersonic first: it is the cause of most of what follows (DFSPH's fluid is incompressible:
  // its Mach number against sqrt(Fluid.stiffness) means nothing and is not judged).
  if (!s.incompressible && st.max_mach > watch(HealthKind::Mach).fail)
    fail(fmt::format(
        "simulation went supersonic {}: particle id {} moves at {:.4g} m/s, Mach {:.3g} (sound "
        "speed sqrt(Fluid.stiffness) = {:.4g} m/s); {}, or lower {}",
        at(), st.mach_id, top_speed, st.max_mach, s.sound_speed, speed_advice(s, top_speed), step_setting(s)));
  const auto contained = [&](HealthKind kind, std::uint64_t count, double depth, std::uint64_t id, double speed,
                             const char* where) {
    const double fraction = static_cast<double>(count) / n;
    if (fraction > watch(kind).fail || depth > h)
      fail(
          fmt::format("simulation lost its fluid {}: {} of {} particles are {} (more than {} % of them, or one "
                      "deeper than h = {:.3g} m); the deepest, particle id {}, is {:.3g} m past the wall at "
                      "{:.3g} m/s; {}",
                      at(), count, particles, where, 100.0 * watch(kind).fail, h, id, depth, speed,
                      wall_advice(s, std::max(top_speed, speed))));
    if (count > 0 && fraction > watch(kind).warn)
      warn(st, kind,
           fmt::format("{} particle{} {} {} (the deepest, particle id {}, {:.3g} m past the wall at {:.3g} m/s); {}",
                       count, count == 1 ? "" : "s", where, at(), id, depth, speed,
                       wall_advice(s, std::max(top_speed, speed))));
  };
  contained(HealthKind::Outside, st.outside, st.outside_depth, st.outside_id, st.outside_speed,
            "outside the container");
  contained(HealthKind::InsideSolid, st.inside_solid, st.inside_depth, st.inside_id, st.inside_speed,
            "inside an obstacle");

  // A floating body sunk into a wall: its contact springs (k = m w^2, w = pi / (10 step)) give
  // under the fluid's load. The depth falls with the step they are made for, as its square under a
  // steady load and in proportion in an impact (a body carried into a wall at speed v sinks about v
  // / w); the warning comes as the depth crosses the threshold, before the deepest point, so the
  // advice is a quarter of the step.
  const double spacing = 2 * s.particle_radius;
  if (st.body_depth > watch(HealthKind::BodyInWall).warn * spacing && s.contact_step > 0)
    warn(st, HealthKind::BodyInWall,
         fmt::format("floating body Obstacles[{}] is {:.3g} m ({:.2g} particle spacings) into the container's {} wall "
                     "{}: its contact springs give under the fluid's load. They are as stiff as steps of {:.3g} s "
                     "allow, and the depth falls with that step (in proportion in an impact, as its square under a "
                     "steady load): lower {} (now {:.3g} s), e.g. to {:.2g} s",
                     st.body_obstacle, st.body_depth, st.body_depth / spacing, st.body_wall, at(), s.contact_step,
                     s.cfl ? "Configuration.cflMaxTimeStepSize" : "Configuration.timeStepSize", s.contact_step,
                     0.25 * s.contact_step));

  if (!s.incompressible && st.max_mach > watch(HealthKind::Mach).warn)
    warn(st, HealthKind::Mach,
         fmt::format("Mach {:.3g} {}: particle id {} moves at {:.4g} m/s (sound speed {:.4g} m/s); the density "
                     "error of weakly compressible SPH grows as Ma^2; {}",
                     st.max_mach, at(), st.mach_id, top_speed, s.sound_speed, speed_advice(s, top_speed)));

  const double stiff_for_1pct = s.stiffness * (st.rho_max - 1.0) / 0.01;
  // What keeps the density near rest: the EOS's stiffness (WCSPH), or DFSPH's solve.
  const auto density_advice = [&] {
    if (s.incompressible)
      return fmt::format(
          "DFSPH's constant-density solve did not hold it: lower Configuration.maxError, raise "
          "Configuration.maxIterations, or take smaller steps (lower {})",
          step_setting(s));
    return fmt::format("Fluid.stiffness >= {:.3g} (now {:.3g}) keeps the compression near 1 %, or lower {}",
                       stiff_for_1pct, s.stiffness, step_setting(s));
  };
  if (st.rho_max > watch(HealthKind::Compression).fail)
    fail(fmt::format("simulation collapsed {}: particle id {} is compressed to {:.3g} times the rest density; {}", at(),
                     st.rho_max_id, st.rho_max, density_advice()));
  if (st.rho_max > watch(HealthKind::Compression).warn)
    warn(st, HealthKind::Compression,
         fmt::format("density {:.3g} times the rest density {} (particle id {}); {}", st.rho_max, at(), st.rho_max_id,
                     density_advice()));
  if (s.tension && 1.0 - st.rho_min > watch(HealthKind::Tension).warn)
    warn(st, HealthKind::Tension,
         fmt::format("density {:.3g} times the rest density {} under Fluid.negativePressure \"allow\": the "
                     "negative pressure pulls particles into clumps; use \"clamp\" for a free surface",
                     st.rho_min, at()));

  if (s.closed) {
    const double growth = (st.energy - initial_energy_) / energy_scale();
    const auto advice = [&] {
      const std::string smaller_step =
          fmt::format("a closed, damped scene cannot gain energy: lower {}", step_setting(s, true));
      const double viscous = s.viscosity / suggested_viscosity(s);
      // A fluid far more viscous than the damping needs: its explicit viscous term is what a long
      // step makes unstable, and more viscosity would make it worse.
      if (!s.implicit_viscosity && viscous > 10)
        return fmt::format(
            "{}, or, the fluid being this viscous (Fluid.viscosity {:.3g}, {:.0f} times Monaghan's alpha = 0.1), "
            "integrate its viscosity backward in time: Fluid.viscositySolver \"implicit\" (stable at any step)",
            smaller_step, s.viscosity, viscous);
      return fmt::format("{} or raise Fluid.viscosity (now {:.3g}; Monaghan's alpha = 0.1 is about {:.3g})",
                         smaller_step, s.viscosity, suggested_viscosity(s));
    };
    if (growth > watch(HealthKind::Energy).fail)
      fail(
          fmt::format("simulation gained energy {}: total energy {:.4g} J is {:.0f} % of its scale above the "
                      "initial {:.4g} J; {}",
                      at(), st.energy, 100.0 * growth, initial_energy_, advice()));
    if (growth > watch(HealthKind::Energy).warn)
      warn(st, HealthKind::Energy,
           fmt::format("total energy {:.4g} J {} is {:.1f} % of its scale above the initial {:.4g} J; {}", st.energy,
                       at(), 100.0 * growth, initial_energy_, advice()));
  }
}

std::vector<std::string> HealthMonitor::warnings() const {
  std::vector<std::pair<std::int64_t, std::size_t>> raised;
  for (std::size_t k = 0; k < kHealthKinds; ++k)
    if (order_[k] != 0) raised.emplace_back(order_[k], k);
  std::sort(raised.begin(), raised.end());
  std::vector<std::string> out;
  for (const auto& [rank, k] : raised) out.push_back(messages_[k]);
  return out;
}

void HealthMonitor::save_state(StateWriter& out) const {
  out.put(initial_energy_);
  out.put(total_mass_);
  out.put(counts_);
  out.put(order_);
  out.put(raised_);
  for (const std::string& m : messages_) out.put(m);
  out.put(max_mach_);
  out.put(rho_max_);
  out.put(rho_min_);
  out.put(max_energy_);
}

void HealthMonitor::load_state(StateReader& in) {
  in.get(initial_energy_);
  in.get(total_mass_);
  in.get(counts_);
  in.get(order_);
  in.get(raised_);
  in.expect(raised_ >= 0 && raised_ <= static_cast<std::int64_t>(kHealthKinds), "a health warning count out of range");
  for (std::size_t k = 0; k < kHealthKinds; ++k) {
    in.get(messages_[k]);
    in.expect(order_[k] >= 0 && order_[k] <= raised_ && (order_[k] == 0) == messages_[k].empty(),
              "a health warning out of range");
  }
  in.get(max_mach_);
  in.get(rho_max_);
  in.get(rho_min_);
  in.get(max_energy_);
}

}  // namespace sph
