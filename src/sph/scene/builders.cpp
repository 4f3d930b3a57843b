#include <sph/scene/builders.h>

#include <cmath>

#include <fmt/format.h>

#include <sph/core/error.h>

namespace sph {

namespace {
template <int D>
std::array<std::int64_t, D> lattice_counts(const Box<D>& b, double dx) {
  std::array<std::int64_t, D> n;
  for (int d = 0; d < D; ++d) n[d] = static_cast<std::int64_t>(std::floor((b.hi[d] - b.lo[d]) / dx + 1e-9));
  return n;
}

/// Calls f(x) for each lattice site of block `blk` (spacing dx, the first half a spacing inside its
/// lower corner), x fastest.
template <int D, class F>
void for_each_block_site(const FluidBlockDesc<D>& blk, double dx, F&& f) {
  const auto n = lattice_counts<D>(blk.box, dx);
  std::array<std::int64_t, 3> m{n[0], n[1], D == 3 ? n[D - 1] : 1};
  for (std::int64_t k = 0; k < m[2]; ++k)
    for (std::int64_t j = 0; j < m[1]; ++j)
      for (std::int64_t i = 0; i < m[0]; ++i) {
        Vec<D, double> x;
        const std::int64_t idx[3] = {i, j, k};
        for (int d = 0; d < D; ++d) x[d] = blk.box.lo[d] + (static_cast<double>(idx[d]) + 0.5) * dx;
        f(x);
      }
}

template <int D>
std::size_t lattice_size(const FluidBlockDesc<D>& blk, double dx) {
  std::size_t c = 1;
  for (auto k : lattice_counts<D>(blk.box, dx)) c *= static_cast<std::size_t>(k);
  return c;
}
}  // namespace

template <int D>
bool block_particle_kept(const SimulationParams<D>& sim, const Vec<D, double>& x) {
  const double r = sim.particle_radius;
  for (std::size_t k = 0; k < sim.shapes.size(); ++k)
    if (obstacle_shape(sim, k) && obstacle_distance(sim, k, x, r).distance < r) return false;
  return true;
}

template <int D>
std::vector<BlockCount> count_block_particles_kept(const SceneBody<D>& body) {
  const double dx = 2.0 * body.sim.particle_radius;
  std::vector<BlockCount> out;
  for (const auto& blk : body.blocks) {
    BlockCount c;
    c.lattice = lattice_size<D>(blk, dx);
    if (!any_shape(body.sim)) {
      c.kept = c.lattice;
    } else {
      for_each_block_site<D>(blk, dx, [&](const Vec<D, double>& x) { c.kept += block_particle_kept(body.sim, x); });
    }
    out.push_back(c);
  }
  return out;
}

template <int D>
std::size_t count_block_particles(const SceneBody<D>& body) {
  std::size_t total = 0;
  if (any_shape(body.sim)) {
    for (const BlockCount& c : count_block_particles_kept<D>(body)) total += c.kept;
    return total;
  }
  const double dx = 2.0 * body.sim.particle_radius;
  for (const auto& blk : body.blocks) total += lattice_size<D>(blk, dx);
  return total;
}

template <int D, std::floating_point R>
ParticleSet<D, R> build_particles(const SceneBody<D>& body, bool keep_initial_positions) {
  const double dx = 2.0 * body.sim.particle_radius;
  ParticleSet<D, R> ps;
  ps.mass = static_cast<R>(body.sim.particle_mass);
  ps.keep_initial_positions(keep_initial_positions);
  ps.reserve(count_block_particles<D>(body));
  const bool shapes = any_shape(body.sim);
  for (std::size_t bi = 0; bi < body.blocks.size(); ++bi) {
    const auto& blk = body.blocks[bi];
    for_each_block_site<D>(blk, dx, [&](const Vec<D, double>& x) {
      if (shapes && !block_particle_kept(body.sim, x)) return;
      for (std::size_t oi = 0; oi < body.sim.obstacles.size(); ++oi) {
        if (obstacle_shape(body.sim, oi)) continue;
        const auto& o = body.sim.obstacles[oi];
        bool in = true;
        for (int d = 0; d < D; ++d) in = in && x[d] > o.lo[d] && x[d] < o.hi[d];
        if (in)
          throw Error(fmt::format("the fluid block overlaps Obstacles[{}]; move the block or the obstacle", oi),
                      fmt::format("FluidBlocks[{}]", bi));
      }
      ps.add(vec_cast<R>(x), vec_cast<R>(blk.velocity));
    });
  }
  return ps;
}

template <int D, std::floating_point R>
Simulation<D, R> make_simulation(const SceneDesc& desc, bool keep_initial_positions) {
  SPH_CHECK(desc.dimension == D, "scene dimension differs from the simulation's");
  const SceneBody<D>& body = desc.body<D>();
  try {
    return Simulation<D, R>(body.sim, build_particles<D, R>(body, keep_initial_positions));
  } catch (const Error& e) {
    throw Error(e.message(), e.where().empty() ? desc.source : desc.source + ": " + e.where());
  }
}

namespace {
template <int D>
std::size_t max_particles_of(const SceneBody<D>& body) {
  std::size_t n = count_block_particles<D>(body);
  for (const auto& e : body.sim.emitters) n += static_cast<std::size_t>(e.max_particles);
  return n;
}

template <int D>
double estimated_bytes_of(const SceneBody<D>& body, std::size_t real_bytes) {
  const SimulationParams<D>& p = body.sim;
  const double n = static_cast<double>(max_particles_of<D>(body));
  double radius = p.kernel_radius;
  if (neighbor_mode_info(p.neighbors).verlet)
    radius += p.verlet_skin > 0 ? p.verlet_skin : kDefaultSkinFraction * p.kernel_radius;
  // The tracked modes: their largest skin (automatic: at most h / 2), and the room of each list.
  const bool tracked = neighbor_mode_info(p.neighbors).tracked;
  if (tracked) radius += p.tracked_skin > 0 ? p.tracked_skin : 0.5 * p.kernel_radius;
  // Lattice neighbors within the list radius: the area or volume of its ball over dx^D.
  const double q = radius / (2.0 * p.particle_radius);
  const double neighbors = D == 2 ? 3.14159265358979 * q * q : 4.18879020478639 * q * q * q;
  // 4 vectors (position, velocity, acceleration, initial position: kept by a run with frames that
  // hold them, the estimate assumes so), 2 scalars (density, pressure), id
  const double fields = 4.0 * D * real_bytes + 2.0 * real_bytes + 8.0;
  const double lists = tracked ? 4.0 * (neighbors * 1.25 + 4.0) * (17.0 / 16.0) + 12.0 + D * real_bytes + 2.0
                               : 4.0 * neighbors * (17.0 / 16.0) + 8.0;  // entries + spare room, offsets
  const double grid = D * real_bytes + 4.0;  // coordinates in cell order (the Morton sort's too), index
  return n * (fields + lists + grid);
}
}  // namespace

std::size_t max_particles(const SceneDesc& desc) {
  return desc.visit_body([]<int D>(const SceneBody<D>& body) { return max_particles_of<D>(body); });
}

double estimated_run_bytes(const SceneDesc& desc) {
  const std::size_t real = desc.precision == Precision::Float ? sizeof(float) : sizeof(double);
  return desc.visit_body([&]<int D>(const SceneBody<D>& body) { return estimated_bytes_of<D>(body, real); });
}

template std::size_t count_block_particles<2>(const SceneBody<2>&);
template std::size_t count_block_particles<3>(const SceneBody<3>&);
template bool block_particle_kept<2>(const SimulationParams<2>&, const Vec<2, double>&);
template bool block_particle_kept<3>(const SimulationParams<3>&, const Vec<3, double>&);
template std::vector<BlockCount> count_block_particles_kept<2>(const SceneBody<2>&);
template std::vector<BlockCount> count_block_particles_kept<3>(const SceneBody<3>&);
#define SPH_INSTANTIATE(D, R)                                                  \
  template ParticleSet<D, R> build_particles<D, R>(const SceneBody<D>&, bool); \
  template Simulation<D, R> make_simulation<D, R>(const SceneDesc&, bool);
SPH_INSTANTIATE(2, float)
SPH_INSTANTIATE(2, double)
SPH_INSTANTIATE(3, float)
SPH_INSTANTIATE(3, double)
#undef SPH_INSTANTIATE

}  // namespace sph
