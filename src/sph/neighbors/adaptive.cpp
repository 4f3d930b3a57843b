#include <sph/neighbors/adaptive.h>

#include <sph/core/error.h>
#include <sph/core/parallel.h>
#include <sph/core/state_stream.h>
#include <sph/core/timer.h>

namespace sph {

template <int D, std::floating_point R>
AdaptiveNeighbors<D, R>::AdaptiveNeighbors(R radius, int full_rebuild_period)
    : radius_(radius), period_(full_rebuild_period) {
  SPH_CHECK(radius > R(0), "neighbor radius must be positive");
  SPH_CHECK(full_rebuild_period >= 1, "full rebuild period must be at least 1");
}

template <int D, std::floating_point R>
void AdaptiveNeighbors<D, R>::update(const ParticleSet<D, R>& particles) {
  // Algorithm 2. The Eq. 7 test itself runs in the solver's force pass, which sets flags_.
  Stopwatch watch;
  const std::size_t n = particles.size();
  flags_.resize(n, 1);  // particles added since the last update start flagged
  const bool full = updates_ % period_ == 0 || lists_.particle_count() == 0 || invalid_;
  invalid_ = false;
  ++updates_;

  std::size_t flagged = n;
  counters_ = {};
  if (full) {
    grid_.build(particles.position, radius_);
    counters_.grid_seconds = watch.lap();
    builder_.build(grid_, particles.position, radius_, lists_);
    this->boundary_.build(particles.position);
  } else {
    flagged = 0;
    for (std::uint8_t f : flags_) flagged += f;
    if (flagged > 0) {
      grid_.build(particles.position, radius_);
      counters_.grid_seconds = watch.lap();
      builder_.rebuild_some(grid_, particles.position, radius_, flags_, lists_);
      this->boundary_.rebuild_some(particles.position, flags_);
    }
  }
  if (full || flagged > 0) counters_.entries_rebuilt = builder_.entries_written();
  std::fill(flags_.begin(), flags_.end(), std::uint8_t{0});  // rebuilt lists start clean
  counters_.lists_seconds = watch.lap();
  counters_.lists_rebuilt = flagged;
  counters_.pairs_stored = lists_.entry_count();
  counters_.boundary_pairs_stored = this->boundary_.lists().entry_count();
}

template <int D, std::floating_point R>
void AdaptiveNeighbors<D, R>::save_state(StateWriter& out) const {
  out.put(updates_);
  out.put(static_cast<std::uint8_t>(invalid_));
  out.put(flags_);
  lists_.save(out);
  this->boundary_.save(out);
}

template <int D, std::floating_point R>
void AdaptiveNeighbors<D, R>::load_state(StateReader& in, std::size_t particles) {
  in.get(updates_);
  invalid_ = in.get<std::uint8_t>() != 0;
  in.get(flags_);
  lists_.load(in);
  this->boundary_.load(in, particles);
  in.expect(updates_ >= 0 && flags_.size() == lists_.particle_count() && flags_.size() <= particles,
            "adaptive neighbor state does not match the particles");
}

template class AdaptiveNeighbors<2, float>;
template class AdaptiveNeighbors<2, double>;
template class AdaptiveNeighbors<3, float>;
template class AdaptiveNeighbors<3, double>;

}  // namespace sph
