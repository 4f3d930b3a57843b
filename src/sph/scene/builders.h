#pragma once
/// \file Builders: turn a SceneDesc into initial particles and a Simulation.

#include <sph/core/particle_set.h>
#include <sph/scene/scene_desc.h>
#include <sph/solver/simulation.h>

namespace sph {

/// Fills each fluid block with particles on a lattice of spacing 2 * particleRadius, the first
/// particle half a spacing inside the block's lower corner, leaving out the sites in or near an
/// obstacle's shape (block_particle_kept). Particles get ids in block order, and the scene's
/// particle mass; the set keeps their initial positions if `keep_initial_positions`.
/// Throws sph::Error if a block overlaps a box obstacle.
template <int D, std::floating_point R>
ParticleSet<D, R> build_particles(const SceneBody<D>& body, bool keep_initial_positions = true);

/// Whether a fluid block's lattice site x keeps its particle: not inside an obstacle's shape
/// (shape.h), nor closer than a particle radius to its surface (box obstacles refuse the block).
template <int D>
bool block_particle_kept(const SimulationParams<D>& sim, const Vec<D, double>& x);

/// A block's lattice sites, and the particles build_particles keeps of them.
struct BlockCount {
  std::size_t lattice = 0, kept = 0;
};
template <int D>
std::vector<BlockCount> count_block_particles_kept(const SceneBody<D>& body);

/// The number of particles build_particles would create (without creating them).
template <int D>
std::size_t count_block_particles(const SceneBody<D>& body);

/// The most particles a run of the scene holds: the blocks' plus every emitter's budget.
std::size_t max_particles(const SceneDesc& desc);

/// About how many bytes a run of the scene needs when it holds max_particles(): the particle
/// fields, the neighbor lists (neighbors per particle from the list radius over the spacing,
/// with the builder's 1/16 spare room) and the grid's copies of the coordinates. Within about
/// 20 % of the peak memory `sph bench` measures (docs/performance.md); used to refuse, before
/// allocating anything, a scene that cannot fit in the machine's memory.
double estimated_run_bytes(const SceneDesc& desc);

/// Builds the initial particles and the simulation of a scene of dimension D (its particles keep
/// their initial positions if `keep_initial_positions`: RunDriver decides, from what reads them).
template <int D, std::floating_point R>
Simulation<D, R> make_simulation(const SceneDesc& desc, bool keep_initial_positions = true);

}  // namespace sph
