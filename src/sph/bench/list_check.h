#pragma once
/// \file An independent check of neighbor lists, for the benchmark: exact for every list up to
/// some thousand points (against brute_force_lists), and for larger sets an exact search for a
/// sample of particles spread over the set plus properties of every list (in range, no self,
/// no duplicates, every entry within the radius, symmetric).

#include <concepts>
#include <cstdint>
#include <functional>
#include <span>
#include <string>

#include <sph/core/vec.h>
#include <sph/neighbors/neighbor_lists.h>

namespace sph {

/// Read-only access to a set of lists: `count` lists, list k is of(k). The check needs no more,
/// so it works for any list storage (and for hand-made, corrupted lists in tests).
struct ListsView {
  std::size_t count = 0;
  std::function<std::span<const std::uint32_t>(std::size_t)> of;
};

/// A view of `lists` (which must outlive it).
ListsView view_of(const NeighborLists& lists);

struct ListCheckOptions {
  /// Up to this many points every list is compared with brute_force_lists (O(N^2)).
  std::size_t full_limit = 20000;
  /// Beyond it, this many particles spread evenly over the index range (first and last
  /// included) get an exact search of their own.
  std::size_t samples = 2000;
};

struct ListCheck {
  bool ok = true;
  std::string method;              ///< how the lists were checked, in words
  std::size_t lists_compared = 0;  ///< lists compared with an exact search
  std::uint64_t entries = 0;       ///< entries of all lists
  std::string problem;             ///< the first problem found, in words ("" when ok)
};

/// Checks `lists`, built on the points positions[perm[k]] (list k belongs to point perm[k] and
/// entry j stands for point perm[j]); with an empty perm, on `positions` as they are. A pair
/// belongs in the lists iff norm2(x_i - x_j) < radius^2 in R arithmetic, i != j. The lists are
/// compared as sets (their order is free). Never throws for bad lists: returns the problem.
template <int D, std::floating_point R>
ListCheck check_neighbor_lists(std::span<const Vec<D, R>> positions, R radius, const ListsView& lists,
                               std::span<const std::uint32_t> perm = {}, const ListCheckOptions& options = {});

}  // namespace sph
