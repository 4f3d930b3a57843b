// The emitters' part of the preflight: nozzles checked particle by particle, the path in front
// of them, emission windows, and room for what they add.

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <string>

#include <fmt/format.h>

#include <sph/scene/builders.h>
#include <sph/scene/preflight.h>
#include <sph/scene/preflight_geometry.h>
#include <sph/solver/nozzle.h>

namespace sph::detail {

namespace {

/// The most steps a scene may have (Configuration.numberOfSteps).
constexpr double kMaxSteps = 1e12;

/// An emitter with the axes of its nozzle (nozzle_axes) and where the preflight names it.
template <int D>
struct Nozzle {
  const EmitterParams<D>& e;
  Vec<D, double> u, w;
  std::string name;  ///< "Emitters[k]"

  int rows() const { return D == 3 ? e.height : 1; }
  Vec<D, double> at(int a, int b) const { return nozzle_position<D>(e, u, w, a, b); }
  std::string particle_text(int a, int b) const {
    return D == 3 ? fmt::format("({}, {}) (of {} x {})", a, b, e.width, e.height)
                  : fmt::format("{} (of {})", a, e.width);
  }
  /// The bounding box of the nozzle's particles (its corners), moved by `shift`.
  Box<D> bounds(const Vec<D, double>& shift) const {
    Box<D> b{at(0, 0) + shift, at(0, 0) + shift};
    for (int a : {0, e.width - 1})
      for (int r : {0, rows() - 1}) {
        const Vec<D, double> x = at(a, r) + shift;
        for (int d = 0; d < D; ++d) b.lo[d] = std::min(b.lo[d], x[d]), b.hi[d] = std::max(b.hi[d], x[d]);
      }
    return b;
  }
};

template <int D>
bool strictly_inside(const Vec<D, double>& x, const Box<D>& o) {
  for (int d = 0; d < D; ++d)
    if (!(x[d] > o.lo[d] && x[d] < o.hi[d])) return false;
  return true;
}

template <int D>
Box<D> grown(Box<D> b, double by) {
  for (int d = 0; d < D; ++d) b.lo[d] -= by, b.hi[d] += by;
  return b;
}

/// A nozzle particle (a, b), moved by `shift`, strictly inside box o; nullopt if none. Row by
/// row (a), the particles of a row inside a box form an interval of b: a few candidates of it
/// are tested with the emitter's own positions.
template <int D>
std::optional<std::array<int, 2>> particle_in(const Nozzle<D>& n, const Vec<D, double>& shift, const Box<D>& o) {
  const Box<D> near = intersection<D>(n.bounds(shift), o);
  for (int d = 0; d < D; ++d)
    if (near.lo[d] > near.hi[d]) return std::nullopt;
  for (int a = 0; a < n.e.width; ++a) {
    const Vec<D, double> x0 = n.at(a, 0) + shift;
    double lo = 0, hi = n.rows() - 1;
    for (int d = 0; d < D && D == 3; ++d) {
      const double step = n.w[d] * n.e.spacing;
      if (step == 0) continue;  // tested on the candidates below
      double t1 = (o.lo[d] - x0[d]) / step, t2 = (o.hi[d] - x0[d]) / step;
      if (t1 > t2) std::swap(t1, t2);
      lo = std::max(lo, t1);
      hi = std::min(hi, t2);
    }
    if (!(lo <= hi)) continue;
    for (double b : {std::round(0.5 * (lo + hi)), std::ceil(lo), std::floor(hi)}) {
      if (b < 0 || b > n.rows() - 1) continue;
      if (strictly_inside<D>(n.at(a, static_cast<int>(b)) + shift, o))
        return std::array<int, 2>{a, static_cast<int>(b)};
    }
  }
  return std::nullopt;
}

/// The box of a fluid block's particles (each with its cell of one spacing around it).
template <int D>
Box<D> filled_box(const Box<D>& b, double dx) {
  Box<D> f = b;
  for (int d = 0; d < D; ++d) f.hi[d] = b.lo[d] + lattice_count(b.lo[d], b.hi[d], dx) * dx;
  return f;
}

/// Every particle of the nozzle at least a particle radius inside the container: its corners
/// are the farthest out (the container is convex).
template <int D>
void check_inside(const ReadContext& ctx, const Nozzle<D>& n, const SimulationParams<D>& sim) {
  const double r = sim.particle_radius;
  const Box<D> room = grown<D>(sim.container, -r);
  double worst = 0;
  std::array<int, 2> corner{0, 0};
  for (int a : {0, n.e.width - 1})
    for (int b : {0, n.rows() - 1}) {
      const Vec<D, double> x = n.at(a, b);
      for (int d = 0; d < D; ++d) {
        const double out = std::max(room.lo[d] - x[d], x[d] - room.hi[d]);
        if (out > worst) worst = out, corner = {a, b};
      }
    }
  if (worst <= 1e-9 * n.e.spacing) return;
  const Box<D> span = n.bounds(Vec<D, double>{});
  Vec<D, double> shift{};
  std::string advice;
  for (int d = 0; d < D && advice.empty(); ++d) {
    if (span.hi[d] - span.lo[d] > room.hi[d] - room.lo[d])
      advice = fmt::format(
          "the nozzle spans {:.4g} m along {}, more than the {:.4g} m the container leaves there: "
          "make it narrower",
          span.hi[d] - span.lo[d], kAxisNames[d], room.hi[d] - room.lo[d]);
    else if (span.lo[d] < room.lo[d])
      shift[d] = room.lo[d] - span.lo[d];
    else if (span.hi[d] > room.hi[d])
      shift[d] = room.hi[d] - span.hi[d];
  }
  if (advice.empty())
    advice = fmt::format("move it to \"translation\": {} or make it narrower", point_text<D>(n.e.origin + shift));
  ctx.fail(n.name, fmt::format("the nozzle's corner particle {}, at {}, is {:.3g} m too close to or outside "
                               "the container {} (every nozzle particle must be at least a particle radius, {:g} m, "
                               "inside it); {}",
                               n.particle_text(corner[0], corner[1]), point_text<D>(n.at(corner[0], corner[1])), worst,
                               box_text<D>(sim.container), r, advice));
}

/// The first nozzle particle (shifted) inside obstacle k or closer than r to it: its box grown by r
/// (particle_in), or for a shape (shape.h) its signed distance below r.
template <int D>
std::optional<std::array<int, 2>> particle_in_obstacle(const Nozzle<D>& n, const Vec<D, double>& shift,
                                                       const SimulationParams<D>& sim, std::size_t k, double r) {
  const ObstacleShape<D>* shape = obstacle_shape(sim, k);
  if (!shape) return particle_in<D>(n, shift, grown<D>(sim.obstacles[k], r));
  if (!shape->inverted && !particle_in<D>(n, shift, grown<D>(sim.obstacles[k], r))) return std::nullopt;
  for (int b = 0; b < n.rows(); ++b)
    for (int a = 0; a < n.e.width; ++a)
      if (obstacle_distance(sim, k, n.at(a, b) + shift, r).distance < r) return std::array<int, 2>{a, b};
  return std::nullopt;
}

/// Every nozzle particle clear (by a particle radius) of every obstacle and of the initial fluid.
template <int D>
void check_clear(const ReadContext& ctx, const Nozzle<D>& n, const SceneBody<D>& body) {
  const SimulationParams<D>& sim = body.sim;
  const double r = sim.particle_radius, dx = 2 * r;
  for (std::size_t i = 0; i < sim.obstacles.size(); ++i)
    if (const auto p = particle_in_obstacle<D>(n, Vec<D, double>{}, sim, i, r))
      ctx.fail(n.name, fmt::format("the nozzle's particle {}, at {}, is inside Obstacles[{}] {} or closer "
                                   "than a particle radius ({:g} m) to it: the emitter would place particles in the "
                                   "solid; move \"translation\" or the obstacle",
                                   n.particle_text((*p)[0], (*p)[1]), point_text<D>(n.at((*p)[0], (*p)[1])), i,
                                   box_text<D>(sim.obstacles[i]), r));
  for (std::size_t i = 0; i < body.blocks.size(); ++i)
    if (const auto p = particle_in<D>(n, Vec<D, double>{}, grown<D>(filled_box<D>(body.blocks[i].box, dx), r)))
      ctx.fail(n.name, fmt::format("the nozzle's particle {}, at {}, is in the fluid of FluidBlocks[{}] {} "
                                   "(closer than a spacing, {:g} m, to its particles): emitted particles would "
                                   "land on the block's; move \"translation\" out of the fluid or shrink the block",
                                   n.particle_text((*p)[0], (*p)[1]), point_text<D>(n.at((*p)[0], (*p)[1])), i,
                                   box_text<D>(body.blocks[i].box), dx));
}

/// A warning when a moving obstacle passes over the nozzle while it emits (checked at 1,024 times
/// over its window within the run): the particles of a batch emitted then would land in the solid.
template <int D>
void check_swept(SceneDesc& desc, const Nozzle<D>& n, const SceneDesc& scene, const SimulationParams<D>& sim) {
  const double run =
      scene.end_time > 0
          ? scene.end_time
          : static_cast<double>(scene.steps) *
                (sim.time_stepping == TimeStepping::Cfl ? std::max(sim.time_step, sim.cfl.max_dt) : sim.time_step);
  const double t0 = std::max(n.e.start_time, 0.0), t1 = std::min(n.e.end_time, run);
  if (!(t1 >= t0)) return;
  const double r = sim.particle_radius;
  constexpr int kSamples = 1024;
  for (std::size_t k = 0; k < sim.obstacles.size(); ++k) {
    const ObstacleMotion<D>& m = obstacle_motion(sim, k);
    if (!m.moves()) continue;
    const Box<D> solid = grown<D>(sim.obstacles[k], r);
    for (int j = 0; j <= kSamples; ++j) {
      const double t = t0 + (t1 - t0) * j / kSamples;
      const RigidPose<D> pose = pose_at(m, t);
      for (int b = 0; b < n.rows(); ++b)
        for (int a = 0; a < n.e.width; ++a)
          if (const Vec<D, double> X = pose.to_rest(n.at(a, b)); [&] {
                if (obstacle_shape(sim, k)) return obstacle_distance(sim, k, X, r).distance < r;
                for (int d = 0; d < D; ++d)
                  if (!(X[d] > solid.lo[d] && X[d] < solid.hi[d])) return false;
                return true;
              }()) {
            desc.warnings.push_back(fmt::format(
                "{}: Obstacles[{}] moves over the nozzle while it emits (at t = {:.6g} s its particle {} is inside "
                "the obstacle or closer than a particle radius to it): a batch emitted then lands in the solid; "
                "move the emitter, or end its window (emitEndTime) before the obstacle comes",
                n.name, k, t, n.particle_text(a, b)));
            return;
          }
    }
  }
}

/// A warning when an obstacle or fluid block lies within kNozzlePathSpacings in front of the
/// nozzle: the first batches run into it (the nozzle swept in half-spacing steps, so that no
/// box a spacing wide is stepped over).
template <int D>
void check_path(SceneDesc& desc, const Nozzle<D>& n, const SceneBody<D>& body) {
  const SimulationParams<D>& sim = body.sim;
  const double r = sim.particle_radius, dx = 2 * r;
  for (int s = 1; s <= 2 * kNozzlePathSpacings; ++s) {
    const double ahead = s * r;
    const Vec<D, double> shift = n.e.direction * ahead;
    std::string hit;
    for (std::size_t i = 0; i < sim.obstacles.size() && hit.empty(); ++i)
      if (particle_in_obstacle<D>(n, shift, sim, i, r))
        hit = fmt::format("Obstacles[{}] {}", i, box_text<D>(sim.obstacles[i]));
    for (std::size_t i = 0; i < body.blocks.size() && hit.empty(); ++i)
      if (particle_in<D>(n, shift, grown<D>(filled_box<D>(body.blocks[i].box, dx), r)))
        hit = fmt::format("the fluid of FluidBlocks[{}] {}", i, box_text<D>(body.blocks[i].box));
    if (hit.empty()) continue;
    desc.warnings.push_back(
        fmt::format("{}: {} is {:.3g} m in front of the nozzle (less than {:g} particle "
                    "spacings): the first batches will run into it at {:g} m/s; move the "
                    "emitter or aim it elsewhere",
                    n.name, hit, ahead, kNozzlePathSpacings, n.e.speed));
    return;
  }
}

/// The first step at which e emits (Simulation::emit: the first whose time reaches the start
/// time less half a step), as a double; `steps` if none of the run's does.
template <int D>
double first_emitting_step(const EmitterParams<D>& e, double steps, double dt) {
  double first = std::clamp(std::ceil(e.start_time / dt - 0.5), 0.0, steps);
  // The estimate is off by a step at most (rounding); past 2^53 steps whole numbers are not exact.
  for (int k = 0; k < 2 && first > 0 && (first - 1) * dt + 0.5 * dt >= e.start_time; ++k) first -= 1;
  for (int k = 0; k < 2 && first < steps && first * dt + 0.5 * dt < e.start_time; ++k) first += 1;
  return first;
}

/// The warnings of an emission window: an emitter that never emits in the run (its window
/// starts after the run's end, or no step falls in it), and one whose window closes before its
/// maxParticles are out (how many will be, and the emitEndTime that would emit them all). A run
/// that merely ends before the budget is out is not warned about: --steps shortens runs on
/// purpose, and a scene's warnings must not depend on whether numberOfSteps came from a flag (a
/// checkpoint's scene reads back to the same SceneDesc, warnings included).
template <int D>
void check_budget(SceneDesc& desc, const Nozzle<D>& n, double dt) {
  const EmitterParams<D>& e = n.e;
  const double steps = static_cast<double>(desc.steps);
  const double first = first_emitting_step<D>(e, kMaxSteps, dt);
  if (emitted_in_run<D>(e, desc.steps, dt) == 0) {
    std::string why, advice;
    if (first >= steps) {
      why = fmt::format("emitStartTime = {:g} s is after the run's end at {:g} s ({} steps of {:g} s)", e.start_time,
                        steps * dt, desc.steps, dt);
      advice = first + 1 > kMaxSteps
                   ? fmt::format("start it earlier (numberOfSteps is at most {:g})", kMaxSteps)
                   : fmt::format("start it earlier or raise numberOfSteps to at least {:.0f}", first + 1);
    } else {
      why = fmt::format("no step of the run falls between emitStartTime = {:g} s and emitEndTime = {:g} s",
                        e.start_time, e.end_time);
      advice = fmt::format("raise emitEndTime to at least {:.6g} s", (first + 0.5) * dt);
    }
    desc.warnings.push_back(fmt::format("{}: the emitter never emits: {}; {}", n.name, why, advice));
    return;
  }
  if (!std::isfinite(e.end_time)) return;
  const std::int64_t in_window = emitted_in_run<D>(e, static_cast<std::int64_t>(kMaxSteps), dt);
  if (in_window >= e.max_particles) return;
  const double per_batch = static_cast<double>(e.width) * n.rows();
  // The step of the last batch needed; half a step more is clear of round-off in its time.
  const double last = first + (std::ceil(static_cast<double>(e.max_particles) / per_batch) - 1) * e.every_steps;
  desc.warnings.push_back(
      fmt::format("{}: only {} of its maxParticles = {} particles are emitted before "
                  "emitEndTime = {:g} s; to emit them all, raise emitEndTime to at least {:.6g} s "
                  "(or lower maxParticles to {})",
                  n.name, in_window, e.max_particles, e.end_time, (last + 0.5) * dt, in_window));
}

/// Room in the container, less its obstacles, for the blocks' particles and those the emitters
/// add in the run, each taking a spacing^D at rest.
template <int D>
void check_room(const ReadContext& ctx, const SceneDesc& desc, const SceneBody<D>& body) {
  const SimulationParams<D>& sim = body.sim;
  const double cell = std::pow(2 * sim.particle_radius, D);
  const double blocks = static_cast<double>(count_block_particles<D>(body));
  double emitted = 0;
  for (const auto& e : sim.emitters) emitted += static_cast<double>(emitted_in_run<D>(e, desc.steps, sim.time_step));
  const double room = free_volume<D>(sim.container, box_obstacles(sim));
  if ((blocks + emitted) * cell <= room * (1 + 1e-9)) return;
  ctx.fail("Emitters", fmt::format("the {:.0f} particles of the fluid blocks and the {:.0f} the emitters add in the "
                                   "run take {:.4g} m^{} at rest (a spacing^{} each), more than the {:.4g} m^{} the "
                                   "container leaves around its obstacles: the fluid would be squeezed; lower the "
                                   "emitters' maxParticles to at most {:.0f} in all",
                                   blocks, emitted, (blocks + emitted) * cell, D, D, room, D,
                                   std::max(0.0, std::floor(room / cell) - blocks)));
}

}  // namespace

template <int D>
std::int64_t emitted_in_run(const EmitterParams<D>& e, std::int64_t steps, double dt) {
  const double n = static_cast<double>(steps);
  const double first = first_emitting_step<D>(e, n, dt);
  double last = n - 1;  // the last step at which it may emit: time not past emitEndTime
  if (std::isfinite(e.end_time)) {
    last = std::clamp(std::floor(e.end_time / dt), -1.0, n - 1);
    for (int k = 0; k < 2 && last + 1 < n && (last + 1) * dt <= e.end_time; ++k) last += 1;
    for (int k = 0; k < 2 && last >= 0 && last * dt > e.end_time; ++k) last -= 1;
  }
  if (!(first <= last)) return 0;
  const double batches = std::floor((last - first) / e.every_steps) + 1;
  const double per_batch = static_cast<double>(e.width) * (D == 3 ? e.height : 1);
  return static_cast<std::int64_t>(std::min(static_cast<double>(e.max_particles), batches * per_batch));
}

template <int D>
void check_emitters(const ReadContext& ctx, SceneDesc& desc, const SceneBody<D>& body) {
  const SimulationParams<D>& sim = body.sim;
  for (std::size_t k = 0; k < sim.emitters.size(); ++k) {
    const EmitterParams<D>& e = sim.emitters[k];
    const auto [u, w] = nozzle_axes<D>(e.direction);
    const Nozzle<D> n{e, u, w, fmt::format("Emitters[{}]", k)};
    if (e.start_time >= e.end_time)
      ctx.fail(n.name + ".emitEndTime",
               fmt::format("emitEndTime = {:g} s is not after emitStartTime = {:g} s, so the emitter would never "
                           "emit; expected an end after the start (or no emitEndTime: no end)",
                           e.end_time, e.start_time));
    check_inside<D>(ctx, n, sim);
    check_clear<D>(ctx, n, body);
    check_path<D>(desc, n, body);
    check_swept<D>(desc, n, desc, sim);
    check_budget<D>(desc, n, sim.time_step);
  }
  if (!sim.emitters.empty()) check_room<D>(ctx, desc, body);
}

template std::int64_t emitted_in_run<2>(const EmitterParams<2>&, std::int64_t, double);
template std::int64_t emitted_in_run<3>(const EmitterParams<3>&, std::int64_t, double);
template void check_emitters<2>(const ReadContext&, SceneDesc&, const SceneBody<2>&);
template void check_emitters<3>(const ReadContext&, SceneDesc&, const SceneBody<3>&);

}  // namespace sph::detail
