#include <sph/neighbors/verlet.h>

#include <algorithm>
#include <cmath>

#include <sph/core/error.h>
#include <sph/core/parallel.h>
#include <sph/core/state_stream.h>
#include <sph/core/timer.h>

namespace sph {

template <int D, std::floating_point R>
VerletNeighbors<D, R>::VerletNeighbors(R radius, R skin, bool clusters)
    : radius_(radius), skin_(skin), clusters_(clusters) {
  SPH_CHECK(radius > R(0), "neighbor radius must be positive");
  SPH_CHECK(skin > R(0), "verlet skin must be positive");
}

template <int D, std::floating_point R>
void VerletNeighbors<D, R>::update(const ParticleSet<D, R>& particles) {
  Stopwatch watch;
  const std::size_t n = particles.size();
  bool rebuild = n != built_at_.size() || (clusters_ ? pairs_.particle_count() : lists_.particle_count()) != n;
  if (!rebuild) {
    // Largest squared displacement since the last build (a max: the same for any thread count).
    chunk_max_.assign(chunk_count(n), R(0));
    parallel_chunks(n, [&](std::size_t c, std::size_t b, std::size_t e) {
      R m = 0;
      for (std::size_t i = b; i < e; ++i) m = std::max(m, norm2(particles.position[i] - built_at_[i]));
      chunk_max_[c] = m;
    });
    R m2 = 0;
    for (R m : chunk_max_) m2 = std::max(m2, m);
    max_disp_ = std::sqrt(m2);
    // Rebuild once a particle may have moved skin / 2 (a hair early, so that rounding in the
    // distance computations can never let a pair within h slip).
    const R trigger = R(0.5) * skin_ * R(0.999);
    rebuild = !(m2 <= trigger * trigger);  // also rebuilds on NaN
  }
  counters_ = {};
  if (rebuild) {
    const R r = radius_ + skin_;
    grid_.build(particles.position, r);
    counters_.grid_seconds = watch.lap();
    if (clusters_) {
      pairs_.build(grid_, particles.position, r);
      lists_built_ = false;
    } else {
      builder_.build(grid_, particles.position, r, lists_);
    }
    // The samples do not move: a fluid particle that moved less than the skin since this build
    // still lists every sample within h.
    this->boundary_.build(particles.position);
    built_at_.assign(particles.position.begin(), particles.position.end());
    max_disp_ = 0;
    counters_.lists_rebuilt = n;
    counters_.entries_rebuilt = clusters_ ? cluster_lanes() : builder_.entries_written();
  }
  counters_.skin = static_cast<double>(skin_);
  counters_.lists_seconds = watch.lap();
  counters_.pairs_stored = clusters_ ? cluster_lanes() : lists_.entry_count();
  counters_.boundary_pairs_stored = this->boundary_.lists().entry_count();
}

template <int D, std::floating_point R>
const NeighborLists& VerletNeighbors<D, R>::lists() const {
  if (clusters_ && !lists_built_) build_lists();
  return lists_;
}

template <int D, std::floating_point R>
void VerletNeighbors<D, R>::build_lists() const {
  if (built_at_.empty()) {
    lists_.clear();
  } else {
    builder_.build(grid_, built_at_, radius_ + skin_, lists_);
  }
  lists_built_ = true;
}

template <int D, std::floating_point R>
void VerletNeighbors<D, R>::save_state(StateWriter& out) const {
  out.put(max_disp_);
  out.put(built_at_);
  // (clusters: the build is a function of its positions, and is made again on load)
  if (!clusters_) lists_.save(out);
  this->boundary_.save(out);
}

template <int D, std::floating_point R>
void VerletNeighbors<D, R>::load_state(StateReader& in, std::size_t particles) {
  in.get(max_disp_);
  in.get(built_at_);
  if (!clusters_) lists_.load(in);
  this->boundary_.load(in, particles);
  in.expect(built_at_.size() <= particles && lists_.particle_count() <= particles,
            "verlet neighbor state does not match the particles");
  if (clusters_) {
    pairs_.clear();
    lists_.clear();
    lists_built_ = false;
    if (!built_at_.empty()) {
      grid_.build(built_at_, radius_ + skin_);
      pairs_.build(grid_, built_at_, radius_ + skin_);
    }
  }
}

template class VerletNeighbors<2, float>;
template class VerletNeighbors<2, double>;
template class VerletNeighbors<3, float>;
template class VerletNeighbors<3, double>;

}  // namespace sph
