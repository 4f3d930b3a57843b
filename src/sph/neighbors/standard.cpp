#include <sph/neighbors/standard.h>

#include <sph/core/error.h>
#include <sph/core/timer.h>

namespace sph {

template <int D, std::floating_point R>
StandardNeighbors<D, R>::StandardNeighbors(R radius) : radius_(radius) {
  SPH_CHECK(radius > R(0), "neighbor radius must be positive");
}

template <int D, std::floating_point R>
void StandardNeighbors<D, R>::update(const ParticleSet<D, R>& particles) {
  Stopwatch watch;
  grid_.build(particles.position, radius_);
  counters_.grid_seconds = watch.lap();
  builder_.build(grid_, particles.position, radius_, lists_);
  this->boundary_.build(particles.position);
  counters_.lists_seconds = watch.lap();
  counters_.lists_rebuilt = particles.size();
  counters_.pairs_stored = lists_.entry_count();
  counters_.entries_rebuilt = lists_.entry_count();
  counters_.boundary_pairs_stored = this->boundary_.lists().entry_count();
}

template <int D, std::floating_point R>
NeighborLists brute_force_lists(std::span<const Vec<D, R>> positions, R radius) {
  const std::size_t n = positions.size();
  const R r2 = radius * radius;
  std::vector<std::vector<std::uint32_t>> lists(n);
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = 0; j < n; ++j)
      if (j != i && norm2(positions[i] - positions[j]) < r2) lists[i].push_back(static_cast<std::uint32_t>(j));
  return NeighborLists::from(lists);
}

template <int D, std::floating_point R>
NeighborLists brute_force_query_lists(std::span<const Vec<D, R>> queries, std::span<const Vec<D, R>> samples,
                                      R radius) {
  const R r2 = radius * radius;
  std::vector<std::vector<std::uint32_t>> lists(queries.size());
  for (std::size_t i = 0; i < queries.size(); ++i)
    for (std::size_t b = 0; b < samples.size(); ++b)
      if (norm2(queries[i] - samples[b]) < r2) lists[i].push_back(static_cast<std::uint32_t>(b));
  return NeighborLists::from(lists);
}

template <int D, std::floating_point R>
BruteForceNeighbors<D, R>::BruteForceNeighbors(R radius) : radius_(radius) {
  SPH_CHECK(radius > R(0), "neighbor radius must be positive");
}

template <int D, std::floating_point R>
void BruteForceNeighbors<D, R>::update(const ParticleSet<D, R>& particles) {
  Stopwatch watch;
  lists_ = brute_force_lists<D, R>(particles.position, radius_);
  if (!this->boundary_.empty())
    boundary_lists_ = brute_force_query_lists<D, R>(particles.position, this->boundary_.samples(), radius_);
  counters_.grid_seconds = 0;
  counters_.lists_seconds = watch.lap();
  counters_.lists_rebuilt = particles.size();
  counters_.pairs_stored = lists_.entry_count();
  counters_.entries_rebuilt = lists_.entry_count();
  counters_.boundary_pairs_stored = boundary_lists_.entry_count();
}

#define SPH_INSTANTIATE(D, R)                                                    \
  template class StandardNeighbors<D, R>;                                        \
  template class BruteForceNeighbors<D, R>;                                      \
  template NeighborLists brute_force_lists<D, R>(std::span<const Vec<D, R>>, R); \
  template NeighborLists brute_force_query_lists<D, R>(std::span<const Vec<D, R>>, std::span<const Vec<D, R>>, R);
SPH_INSTANTIATE(2, float)
SPH_INSTANTIATE(2, double)
SPH_INSTANTIATE(3, float)
SPH_INSTANTIATE(3, double)
#undef SPH_INSTANTIATE

}  // namespace sph
