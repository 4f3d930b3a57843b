#include <sph/neighbors/boundary_lists.h>

#include <algorithm>

#include <sph/core/error.h>
#include <sph/core/state_stream.h>

namespace sph {

template <int D, std::floating_point R>
void BoundaryLists<D, R>::set_samples(std::span<const Vec<D, R>> samples, R radius) {
  SPH_CHECK(radius > R(0), "boundary list radius must be positive");
  samples_.assign(samples.begin(), samples.end());
  radius_ = radius;
  lists_.clear();
  if (!samples_.empty()) grid_.build(samples_, radius_);
}

template <int D, std::floating_point R>
void BoundaryLists<D, R>::move_samples(std::span<const Vec<D, R>> samples) {
  SPH_CHECK(samples.size() == samples_.size(), "moved boundary samples: as many as were set");
  if (samples_.empty()) return;
  std::copy(samples.begin(), samples.end(), samples_.begin());
  grid_.build(samples_, radius_);
  moved_ = true;
}

template <int D, std::floating_point R>
void BoundaryLists<D, R>::build(std::span<const Vec<D, R>> fluid) {
  if (samples_.empty()) return;
  builder_.build_queries(grid_, fluid, radius_, lists_);
  moved_ = false;
}

template <int D, std::floating_point R>
void BoundaryLists<D, R>::rebuild_some(std::span<const Vec<D, R>> fluid, std::span<const std::uint8_t> rebuild) {
  if (samples_.empty()) return;
  if (moved_) return build(fluid);
  builder_.rebuild_some_queries(grid_, fluid, radius_, rebuild, lists_);
}

template <int D, std::floating_point R>
void BoundaryLists<D, R>::save(StateWriter& out) const {
  out.put(static_cast<std::uint64_t>(samples_.size()));
  if (!samples_.empty()) lists_.save(out);
}

template <int D, std::floating_point R>
void BoundaryLists<D, R>::load(StateReader& in, std::size_t particles) {
  in.expect(in.get<std::uint64_t>() == samples_.size(), "a different number of boundary samples");
  if (samples_.empty()) return;
  lists_.load(in, samples_.size());
  in.expect(lists_.particle_count() <= particles, "boundary lists do not match the particles");
}

template class BoundaryLists<2, float>;
template class BoundaryLists<2, double>;
template class BoundaryLists<3, float>;
template class BoundaryLists<3, double>;

}  // namespace sph
