#pragma once
/// \file ListAuditor: measures what a strategy's lists miss, against exact lists.

#include <cstdint>
#include <span>
#include <vector>

#include <sph/neighbors/cluster_pairs.h>
#include <sph/neighbors/list_builder.h>
#include <sph/neighbors/neighbor_lists.h>
#include <sph/neighbors/uniform_grid.h>

namespace sph {

/// What a set of lists misses at one instant.
struct ListAudit {
  /// Directed pairs (i, j) closer than h with j missing from i's list (a pair missing from
  /// both lists counts twice, as the solver misses it twice).
  std::uint64_t missed_pairs = 0;
  /// Particles with at least one missed neighbor.
  std::uint64_t particles_missing = 0;
  /// Largest penetration (h - r) / h of a missed pair: 0 when none is missed, up to 1.
  double max_penetration = 0;
};

/// Compares lists with the exact lists of all pairs strictly closer than h, built from a fresh
/// grid (itself tested against brute force). Costs about one standard rebuild plus a sort of
/// each list. Deterministic for any thread count.
template <int D, std::floating_point R>
class ListAuditor {
 public:
  ListAudit audit(std::span<const Vec<D, R>> positions, const NeighborLists& lists, R h);
  /// The same for cluster pairs (verlet_clusters): the pairs (i, j) closer than h whose clusters
  /// are not listed, i's cluster missing j's.
  ListAudit audit_clusters(std::span<const Vec<D, R>> positions, const ClusterPairs<D, R>& pairs, R h);
  /// The same for boundary lists: the fluid-boundary pairs (particle i, sample b) closer than h
  /// that i's boundary list misses (missed_pairs counts each once: the solver visits the pair
  /// from the fluid side only).
  ListAudit audit_boundary(std::span<const Vec<D, R>> positions, std::span<const Vec<D, R>> samples,
                           const NeighborLists& lists, R h);

 private:
  /// Counts what the lists miss of exact_, the pairs of positions[i] and others[j] closer than h:
  /// pair (i, j) is listed when listed(i) holds key(j) (both given as index -> value functions).
  template <class Listed, class Key>
  ListAudit compare(std::span<const Vec<D, R>> positions, std::span<const Vec<D, R>> others, const Listed& listed,
                    const Key& key, R h);

  UniformGrid<D, R> grid_, sample_grid_;
  ListBuilder<D, R> builder_;
  NeighborLists exact_;
  std::vector<std::vector<std::uint32_t>> scratch_;  // per chunk: a sorted copy of one list
  std::vector<ListAudit> partial_;
};

extern template class ListAuditor<2, float>;
extern template class ListAuditor<2, double>;
extern template class ListAuditor<3, float>;
extern template class ListAuditor<3, double>;

}  // namespace sph
