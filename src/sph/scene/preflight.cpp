#include <sph/scene/preflight.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include <fmt/format.h>

#include <sph/scene/builders.h>
#include <sph/scene/preflight_geometry.h>
#include <sph/solver/wcsph.h>

namespace sph {

namespace {

using detail::box_text;
using detail::kAxisNames;
using detail::point_text;
using detail::ReadContext;

/// Whether a particle of the block filling box b at spacing dx lies strictly inside box o (as
/// build_particles tests it): on each axis on its own, as the lattice is a product of axes.
template <int D>
bool lattice_enters(const Box<D>& b, double dx, const Box<D>& o) {
  for (int d = 0; d < D; ++d) {
    const double n = detail::lattice_count(b.lo[d], b.hi[d], dx);
    auto x = [&](double i) { return b.lo[d] + (i + 0.5) * dx; };
    // The first lattice index past o.lo: estimated, then stepped to the exact one.
    double i = std::clamp(std::ceil((o.lo[d] - b.lo[d]) / dx - 0.5), 0.0, n);
    while (i > 0 && x(i - 1) > o.lo[d]) i -= 1;
    while (i < n && !(x(i) > o.lo[d])) i += 1;
    if (!(i < n && x(i) < o.hi[d])) return false;
  }
  return true;
}

/// How to move box `cut` (named cut_name) off box `keep`: shrink it along the axis and side
/// that keep the most of it (at least one spacing dx), to end where keep starts or start where
/// it ends. Empty if no such shrinking exists (cut lies within keep along every axis).
template <int D>
std::string separation_advice(const Box<D>& cut, const std::string& cut_name, const Box<D>& keep,
                              const std::string& keep_name, double dx) {
  std::string best;
  double best_kept = -1;
  for (int d = 0; d < D; ++d) {
    const double size = cut.hi[d] - cut.lo[d];
    Box<D> moved = cut;
    if (keep.lo[d] - cut.lo[d] >= dx && (keep.lo[d] - cut.lo[d]) / size > best_kept) {
      best_kept = (keep.lo[d] - cut.lo[d]) / size;
      moved.hi[d] = keep.lo[d];
      best = fmt::format("shrink {} to end where {} starts along {}: \"end\": {}", cut_name, keep_name, kAxisNames[d],
                         point_text<D>(moved.hi));
      moved.hi[d] = cut.hi[d];
    }
    if (cut.hi[d] - keep.hi[d] >= dx && (cut.hi[d] - keep.hi[d]) / size > best_kept) {
      best_kept = (cut.hi[d] - keep.hi[d]) / size;
      moved.lo[d] = keep.hi[d];
      best = fmt::format("shrink {} to start where {} ends along {}: \"start\": {}", cut_name, keep_name, kAxisNames[d],
                         point_text<D>(moved.lo));
    }
  }
  return best;
}

/// An obstacle wholly or partly outside the container is refused: the walls already bound the
/// fluid there, so it is a typo (or a unit mistake) and its faces would push particles out.
template <int D>
void check_obstacles_inside(const ReadContext& ctx, const SimulationParams<D>& sim) {
  const Box<D>& c = sim.container;
  for (std::size_t i = 0; i < sim.obstacles.size(); ++i) {
    const Box<D>& o = sim.obstacles[i];
    bool inside = true, apart = false;
    for (int d = 0; d < D; ++d) {
      inside = inside && o.lo[d] >= c.lo[d] && o.hi[d] <= c.hi[d];
      apart = apart || o.hi[d] <= c.lo[d] || o.lo[d] >= c.hi[d];
    }
    // (a shape at rest or on a motion may reach past the walls: its samples and springs there are
    // dropped, so a mesh floor wider than the container is fine; a floating one starts inside)
    if (inside || (obstacle_shape(sim, i) && !obstacle_body(sim, i).dynamic && !apart)) continue;
    const std::string where = fmt::format("Obstacles[{}]", i);
    if (apart)
      ctx.fail(where, fmt::format("the obstacle {} lies wholly outside the container {}: it can never touch the "
                                  "fluid; move it inside the container or remove it",
                                  box_text<D>(o), box_text<D>(c)));
    if (obstacle_shape(sim, i)) {
      // A floating polygon or mesh: clipping its box would not change the shape; moving it does.
      Vec<D, double> shift{};
      bool fits = true;
      for (int d = 0; d < D; ++d) {
        fits = fits && o.hi[d] - o.lo[d] <= c.hi[d] - c.lo[d];
        shift[d] = o.lo[d] < c.lo[d] ? c.lo[d] - o.lo[d] : o.hi[d] > c.hi[d] ? c.hi[d] - o.hi[d] : 0.0;
      }
      const char* shape = D == 2 ? "polygon" : "mesh";
      ctx.fail(where, fmt::format("a floating {} must start wholly inside the container {}, and this one reaches "
                                  "{} (its bounding box); {}",
                                  shape, box_text<D>(c), box_text<D>(o),
                                  fits ? fmt::format("move it by {} ({})", point_text<D>(shift),
                                                     D == 2 ? "add it to each vertex" : "add it to \"translation\"")
                                       : fmt::format("it is larger than the container: make it smaller{}",
                                                     D == 2 ? "" : " (\"scale\")")));
    }
    Box<D> clipped;
    for (int d = 0; d < D; ++d) {
      clipped.lo[d] = std::max(o.lo[d], c.lo[d]);
      clipped.hi[d] = std::min(o.hi[d], c.hi[d]);
    }
    ctx.fail(where, fmt::format("the obstacle {} is partly outside the container {}; the container's walls already "
                                "hold the fluid there: clip it to {} (\"start\": {}, \"end\": {})",
                                box_text<D>(o), box_text<D>(c), box_text<D>(clipped), point_text<D>(clipped.lo),
                                point_text<D>(clipped.hi)));
  }
}

/// A floating body (Obstacles[].dynamic) much lighter than the fluid draws a warning: the
/// coupling, explicit between the fluid's step and the body's with weakly compressible SPH
/// (SPlisHSPlasH's Akinci coupling has the same limit), grows unstable as the body's mass falls
/// below the fluid it displaces; DFSPH's solves take the body's answer to their pressure, but its
/// friction and viscosity stay explicit. (Like every obstacle it starts inside the container: the
/// scene reader refuses one that does not.)
template <int D>
void check_bodies(SceneDesc& desc, const SimulationParams<D>& sim) {
  for (std::size_t k = 0; k < sim.obstacles.size(); ++k) {
    const BodyParams<D>& b = obstacle_body(sim, k);
    if (b.dynamic && b.density < 0.1 * sim.fluid.rest_density)
      desc.warnings.push_back(fmt::format(
          "Obstacles[{}]: a floating body of density {:g} is less than a tenth of the fluid's ({:g}): the coupling "
          "between the fluid's step and the body's may grow unstable; make it denser, or expect to shorten the steps",
          k, b.density, sim.fluid.rest_density));
  }
}

/// A moving obstacle must stay inside the container: its corners are checked at 4,096 times
/// evenly over the run (and at each key of keyframes), and one that goes farther than the kernel
/// radius past a wall is refused (a unit mistake, or an amplitude too large for the tank), as is a
/// motion whose pose overflows (not finite). Less is allowed: a paddle standing on the floor that
/// tilts a little pokes into the floor, which holds the fluid there anyway. With fixed steps, a
/// surface that moves more than 0.4 particle diameters in a step, or an oscillation shorter than
/// 20 steps, draws a warning (CFL steps take the obstacles' speed into their length).
template <int D>
void check_motions(const ReadContext& ctx, SceneDesc& desc, const SimulationParams<D>& sim) {
  const Box<D>& c = sim.container;
  const bool cfl = sim.time_stepping == TimeStepping::Cfl;
  // The run's end: its end time, or its steps at their longest.
  const double run = desc.end_time > 0 ? desc.end_time
                                       : static_cast<double>(desc.steps) *
                                             (cfl ? std::max(sim.time_step, sim.cfl.max_dt) : sim.time_step);
  for (std::size_t k = 0; k < sim.obstacles.size(); ++k) {
    const ObstacleMotion<D>& m = obstacle_motion(sim, k);
    if (!m.moves()) continue;
    const std::string where = fmt::format("Obstacles[{}].motion", k);
    std::vector<double> times;
    constexpr int kSamples = 4096;
    for (int j = 0; j <= kSamples; ++j) times.push_back(run * j / kSamples);
    for (const MotionKey<D>& key : m.keys)
      if (key.time <= run) times.push_back(key.time);
    double fastest = 0;
    for (const double t : times) {
      const RigidPose<D> pose = pose_at(m, t);
      // (its rates finite too: a NaN corner speed would not raise the largest)
      const double speed = pose_surface_speed<D>(pose, sim.obstacles[k].lo, sim.obstacles[k].hi);
      const bool rates = all_finite(pose.velocity) && all_finite(pose.angular_velocity) && std::isfinite(speed);
      fastest = std::max(fastest, speed);
      for (int corner = 0; corner < (1 << D); ++corner) {
        const Vec<D, double> X = box_corner<D>(sim.obstacles[k].lo, sim.obstacles[k].hi, corner);
        const Vec<D, double> x = pose.place(X);
        if (!all_finite(x) || !rates)
          ctx.fail(where, fmt::format("the motion's pose at t = {:.6g} s is not finite (a value too large: an "
                                      "angle, a rate or a period that overflows); expected a motion of a size the "
                                      "container holds",
                                      t));
        double out = 0;
        for (int d = 0; d < D; ++d) out = std::max({out, c.lo[d] - x[d], x[d] - c.hi[d]});
        if (out > sim.kernel_radius)
          ctx.fail(where,
                   fmt::format("the motion takes the obstacle out of the container {}: at t = {:.6g} s its "
                               "corner {} is at {}, {:.3g} m past the wall (at most the kernel radius, {:.3g} "
                               "m, is allowed); make the motion smaller, or the obstacle, so that it stays inside",
                               box_text<D>(c), t, point_text<D>(X), point_text<D>(x), out, sim.kernel_radius));
      }
    }
    if (cfl) continue;
    const double dx = 2 * sim.particle_radius;
    if (fastest * sim.time_step > 0.4 * dx)
      desc.warnings.push_back(fmt::format(
          "{}: the obstacle's surface moves up to {:.3g} m/s, {:.2g} particle diameters in a step of {:.3g} s (more "
          "than 0.4): the fluid next to it cannot follow; take steps of at most {:.3g} s, or cflMethod \"cfl\" "
          "(its steps count the obstacles' speed)",
          where, fastest, fastest * sim.time_step / dx, sim.time_step, 0.4 * dx / fastest));
    if (m.type == MotionType::Oscillation && m.period < 20 * sim.time_step)
      desc.warnings.push_back(
          fmt::format("{}: a period of {:.3g} s is only {:.3g} steps of {:.3g} s: the motion is "
                      "sampled too coarsely; take steps of at most {:.3g} s (period / 20)",
                      where, m.period, m.period / sim.time_step, sim.time_step, m.period / 20));
  }
}

/// Obstacles covering the whole container are refused (the fluid has no room at all).
template <int D>
void check_obstacles_leave_room(const ReadContext& ctx, const SimulationParams<D>& sim) {
  if (sim.obstacles.empty()) return;
  const double free = detail::free_volume<D>(sim.container, detail::box_obstacles(sim));
  if (free > 1e-9 * detail::volume<D>(sim.container)) return;
  ctx.fail("Obstacles", fmt::format("the {} obstacles cover the whole container {}: there is no room for the fluid; "
                                    "make them smaller or the container larger",
                                    sim.obstacles.size(), box_text<D>(sim.container)));
}

/// Coordinates far from the origin for the precision: positions are stored at the precision of
/// the run, so a coordinate |x| is known to |x| * epsilon, which must stay a small fraction of
/// the spacing (densities sum the kernel over distances of about one spacing).
template <int D>
void check_coordinates(const ReadContext& ctx, SceneDesc& desc, const SimulationParams<D>& sim) {
  const bool is_float = desc.precision == Precision::Float;
  const double eps = is_float ? std::ldexp(1.0, -23) : std::ldexp(1.0, -52);
  const double dx = 2.0 * sim.particle_radius;
  double far = 0;
  for (int d = 0; d < D; ++d) far = std::max({far, std::abs(sim.container.lo[d]), std::abs(sim.container.hi[d])});
  const double fraction = far * eps / dx;
  if (fraction <= kCoordinateWarnFraction) return;
  Vec<D, double> centre;
  for (int d = 0; d < D; ++d) centre[d] = 0.5 * (sim.container.lo[d] + sim.container.hi[d]);
  const std::string advice =
      fmt::format("{}move the scene near the origin: subtract {} (the container's centre) from every coordinate",
                  is_float ? "use \"precision\": \"double\", or " : "", point_text<D>(centre));
  const std::string what = fmt::format(
      "coordinates reach {:g} m from the origin, where {} positions are {:.3g} m apart: {:.3g} of the particle "
      "spacing {:g} m",
      far, is_float ? "float" : "double", far * eps, fraction, dx);
  if (fraction > kCoordinateRefuseFraction)
    ctx.fail("Container", fmt::format("{} (more than {:g}), so the initial densities would be wrong by about 1 % or "
                                      "more; {}",
                                      what, kCoordinateRefuseFraction, advice));
  desc.warnings.push_back(fmt::format("Container: {} (more than {:g}), so densities lose precision; {}", what,
                                      kCoordinateWarnFraction, advice));
}

template <int D>
std::string blocks_advice(const Box<D>& a, const std::string& a_name, const Box<D>& b, const std::string& b_name,
                          double dx) {
  std::string advice = separation_advice<D>(b, b_name, a, a_name, dx);
  if (advice.empty()) advice = separation_advice<D>(a, a_name, b, b_name, dx);
  return advice.empty() ? fmt::format("one lies within the other: remove {} or {}", a_name, b_name) : advice;
}

template <int D>
std::string obstacle_advice(const Box<D>& b, const std::string& b_name, const Box<D>& o, const std::string& o_name,
                            double dx) {
  const std::string advice = separation_advice<D>(b, b_name, o, o_name, dx);
  return advice.empty() ? fmt::format("the block lies within {}: move it or the obstacle", o_name)
                        : advice + "; or move the obstacle";
}

/// Overlapping fluid blocks: particles of two blocks closer than half a spacing (coincident ones
/// in the worst case) repel with huge pressures from step 0.
template <int D>
void check_blocks_apart(const ReadContext& ctx, const SceneBody<D>& body) {
  const double dx = 2.0 * body.sim.particle_radius;
  for (std::size_t j = 1; j < body.blocks.size(); ++j)
    for (std::size_t i = 0; i < j; ++i) {
      const Box<D>& a = body.blocks[i].box;
      const Box<D>& b = body.blocks[j].box;
      const double gap = detail::lattice_gap<D>(a, b, dx);
      if (gap >= kMinBlockGapSpacings * dx) continue;
      const std::string first = fmt::format("FluidBlocks[{}]", i), second = fmt::format("FluidBlocks[{}]", j);
      ctx.fail(second, fmt::format("the fluid block {} overlaps {} {} in {}: particles of the two would be {:.3g} m "
                                   "apart (less than half the spacing {:g} m) and push each other apart at once; {}",
                                   box_text<D>(b), first, box_text<D>(a), box_text<D>(detail::intersection<D>(a, b)),
                                   gap, dx, blocks_advice<D>(a, first, b, second, dx)));
    }
}

/// A block with a particle inside a box obstacle is refused (build_particles refuses it too,
/// later); the particles of a block in or near a shape are left out (block_particle_kept), with a
/// warning that says how many, and a block left with none is refused.
template <int D>
void check_blocks_clear_of_obstacles(const ReadContext& ctx, SceneDesc& desc, const SceneBody<D>& body) {
  const double dx = 2.0 * body.sim.particle_radius;
  if (any_shape(body.sim)) {
    const std::vector<BlockCount> counts = count_block_particles_kept<D>(body);
    for (std::size_t bi = 0; bi < counts.size(); ++bi) {
      const BlockCount& c = counts[bi];
      if (c.lattice == c.kept) continue;
      if (c.kept == 0)
        ctx.fail(fmt::format("FluidBlocks[{}]", bi),
                 "the fluid block lies wholly inside the obstacles' shapes (or "
                 "within a particle radius of them): move it");
      desc.warnings.push_back(fmt::format(
          "FluidBlocks[{}]: {} of its {} particles are inside an obstacle's shape or within a particle radius of its "
          "surface, and are left out",
          bi, c.lattice - c.kept, c.lattice));
    }
  }
  for (std::size_t bi = 0; bi < body.blocks.size(); ++bi)
    for (std::size_t oi = 0; oi < body.sim.obstacles.size(); ++oi) {
      if (obstacle_shape(body.sim, oi)) continue;
      const Box<D>& b = body.blocks[bi].box;
      const Box<D>& o = body.sim.obstacles[oi];
      if (!lattice_enters<D>(b, dx, o)) continue;
      const std::string block = fmt::format("FluidBlocks[{}]", bi), obstacle = fmt::format("Obstacles[{}]", oi);
      ctx.fail(block, fmt::format("the fluid block {} overlaps {} {} in {}: its particles there would start inside "
                                  "the solid; {}",
                                  box_text<D>(b), obstacle, box_text<D>(o), box_text<D>(detail::intersection<D>(b, o)),
                                  obstacle_advice<D>(b, block, o, obstacle, dx)));
    }
}

/// Fluid.particleMass far from the lattice mass: the initial density is that many times rho0.
template <int D>
void check_mass(const ReadContext& ctx, SceneDesc& desc, const SimulationParams<D>& sim) {
  const double lattice =
      lattice_mass<D>(sim.fluid.rest_density, 2.0 * sim.particle_radius, sim.kernel_radius, sim.fluid.kernel);
  if (!(std::isfinite(lattice) && lattice > 0)) return;  // the reader refuses a default mass like that
  const double ratio = sim.particle_mass / lattice;
  const double factor = std::max(ratio, 1 / ratio);
  if (!(factor > kMassWarnFactor)) return;
  const std::string what = fmt::format(
      "particleMass = {:.4g} kg is {:.3g} times the lattice mass {:.4g} kg, so the initial density would be about "
      "{:.3g} kg/m^{} instead of density0 = {:g}",
      sim.particle_mass, ratio, lattice, ratio * sim.fluid.rest_density, D, sim.fluid.rest_density);
  const std::string advice = fmt::format("use particleMass {:.6g} (or leave it out: that is the default)", lattice);
  if (factor > kMassRefuseFactor)
    ctx.fail("Fluid.particleMass", fmt::format("{}: more than {:g} times off, the fluid would {} at once; {}", what,
                                               kMassRefuseFactor, ratio > 1 ? "explode" : "collapse", advice));
  desc.warnings.push_back(
      fmt::format("Fluid.particleMass: {}: more than {:g} times off, the fluid will {} at the "
                  "start; {}",
                  what, kMassWarnFactor, ratio > 1 ? "expand" : "contract", advice));
}

/// negativePressure "allow" with a free surface: tension pulls surface particles into clumps.
template <int D>
void check_allow_on_free_surface(SceneDesc& desc, const SceneBody<D>& body) {
  const SimulationParams<D>& sim = body.sim;
  if (sim.fluid.negative_pressure != NegativePressure::Allow) return;
  const double dx = 2.0 * sim.particle_radius;
  const double room = detail::free_volume<D>(sim.container, detail::box_obstacles(sim));
  const double fluid = static_cast<double>(count_block_particles<D>(body)) * std::pow(dx, D);
  const double filled = room > 0 ? fluid / room : 1;
  if (sim.emitters.empty() && filled >= 0.99) return;  // the fluid fills the container: no free surface
  desc.warnings.push_back(fmt::format(
      "Fluid.negativePressure: \"allow\" with a free surface (the fluid blocks fill {:.0f} % of the room in the "
      "container{}): p = k (rho - rho0) < 0 is a tension that clumps the particles of a free surface (the paper's "
      "dam break turns to gas with it); use \"clamp\" (the default)",
      100 * filled, sim.emitters.empty() ? "" : ", and emitters add fluid"));
}

}  // namespace

namespace detail {

template <int D>
double lattice_gap(const Box<D>& a, const Box<D>& b, double dx) {
  double gap2 = 0;
  for (int d = 0; d < D; ++d) {
    // Differences of the two lattices' coordinates: c + k dx, k from -(na - 1) to nb - 1.
    const double na = lattice_count(a.lo[d], a.hi[d], dx), nb = lattice_count(b.lo[d], b.hi[d], dx);
    const double c = b.lo[d] - a.lo[d];
    const double k = std::clamp(std::round(-c / dx), -(na - 1), nb - 1);
    const double along = std::abs(c + k * dx);
    gap2 += along * along;
  }
  return std::sqrt(gap2);
}

template double lattice_gap<2>(const Box<2>&, const Box<2>&, double);
template double lattice_gap<3>(const Box<3>&, const Box<3>&, double);

}  // namespace detail

template <int D>
void preflight(SceneDesc& desc, const detail::ReadContext& ctx) {
  SceneBody<D>& body = desc.body<D>();
  const SimulationParams<D>& sim = body.sim;
  check_obstacles_inside<D>(ctx, sim);
  check_motions<D>(ctx, desc, sim);
  check_bodies<D>(desc, sim);
  check_obstacles_leave_room<D>(ctx, sim);
  check_coordinates<D>(ctx, desc, sim);
  check_blocks_apart<D>(ctx, body);
  check_blocks_clear_of_obstacles<D>(ctx, desc, body);
  detail::check_emitters<D>(ctx, desc, body);
  check_mass<D>(ctx, desc, sim);
  check_allow_on_free_surface<D>(desc, body);
}

template void preflight<2>(SceneDesc&, const detail::ReadContext&);
template void preflight<3>(SceneDesc&, const detail::ReadContext&);

}  // namespace sph
