#include <sph/neighbors/audit.h>

#include <algorithm>
#include <cmath>

#include <sph/core/error.h>
#include <sph/core/parallel.h>

namespace sph {

template <int D, std::floating_point R>
ListAudit ListAuditor<D, R>::audit(std::span<const Vec<D, R>> positions, const NeighborLists& lists, R h) {
  const std::size_t n = positions.size();
  SPH_CHECK(lists.particle_count() == n, "audited lists must cover every particle");
  ListAudit total;
  if (n == 0) return total;
  grid_.build(positions, h);
  builder_.build(grid_, positions, h, exact_);
  return compare(
      positions, positions, [&](std::size_t i) { return lists.of(i); }, [](std::uint32_t j) { return j; }, h);
}

template <int D, std::floating_point R>
ListAudit ListAuditor<D, R>::audit_clusters(std::span<const Vec<D, R>> positions, const ClusterPairs<D, R>& pairs,
                                            R h) {
  const std::size_t n = positions.size();
  SPH_CHECK(pairs.particle_count() == n, "audited cluster pairs must cover every particle");
  if (n == 0) return {};
  grid_.build(positions, h);
  builder_.build(grid_, positions, h, exact_);
  return compare(
      positions, positions, [&](std::size_t i) { return pairs.of(pairs.cluster_of(i)); },
      [&](std::uint32_t j) { return pairs.cluster_of(j); }, h);
}

template <int D, std::floating_point R>
ListAudit ListAuditor<D, R>::audit_boundary(std::span<const Vec<D, R>> positions, std::span<const Vec<D, R>> samples,
                                            const NeighborLists& lists, R h) {
  const std::size_t n = positions.size();
  if (samples.empty() || n == 0) return {};
  SPH_CHECK(lists.particle_count() == n, "audited boundary lists must cover every particle");
  sample_grid_.build(samples, h);
  builder_.build_queries(sample_grid_, positions, h, exact_);
  return compare(
      positions, samples, [&](std::size_t i) { return lists.of(i); }, [](std::uint32_t j) { return j; }, h);
}

template <int D, std::floating_point R>
template <class Listed, class Key>
ListAudit ListAuditor<D, R>::compare(std::span<const Vec<D, R>> positions, std::span<const Vec<D, R>> others,
                                     const Listed& listed_of, const Key& key, R h) {
  const std::size_t n = positions.size();
  ListAudit total;
  const std::size_t chunks = chunk_count(n);
  if (scratch_.size() < chunks) scratch_.resize(chunks);
  partial_.assign(chunks, ListAudit{});
  parallel_chunks(n, [&](std::size_t c, std::size_t b, std::size_t e) {
    std::vector<std::uint32_t>& have = scratch_[c];
    ListAudit a;
    for (std::size_t i = b; i < e; ++i) {
      const auto want = exact_.of(i);
      if (want.empty()) continue;
      const std::span<const std::uint32_t> listed = listed_of(i);
      have.assign(listed.begin(), listed.end());
      std::sort(have.begin(), have.end());
      std::uint64_t missed = 0;
      for (std::uint32_t j : want) {
        if (std::binary_search(have.begin(), have.end(), key(j))) continue;
        ++missed;
        const double r = std::sqrt(static_cast<double>(norm2(positions[i] - others[j])));
        a.max_penetration = std::max(a.max_penetration, (static_cast<double>(h) - r) / static_cast<double>(h));
      }
      a.missed_pairs += missed;
      a.particles_missing += missed > 0 ? 1 : 0;
    }
    partial_[c] = a;
  });
  for (const ListAudit& a : partial_) {
    total.missed_pairs += a.missed_pairs;
    total.particles_missing += a.particles_missing;
    total.max_penetration = std::max(total.max_penetration, a.max_penetration);
  }
  return total;
}

template class ListAuditor<2, float>;
template class ListAuditor<2, double>;
template class ListAuditor<3, float>;
template class ListAuditor<3, double>;

}  // namespace sph
