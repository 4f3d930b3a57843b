#pragma once
/// \file Building full neighbor lists from a UniformGrid, in parallel and deterministically.

#include <span>
#include <vector>

#include <sph/neighbors/neighbor_lists.h>
#include <sph/neighbors/uniform_grid.h>

namespace sph {

/// Builds the full lists of all points within `radius` (strictly closer) from a grid built on
/// the same points. The order of each list depends only on the input, never on thread count.
/// Keeps its scratch buffers between calls so that rebuilding allocates nothing in steady state.
template <int D, std::floating_point R>
class ListBuilder {
 public:
  void build(const UniformGrid<D, R>& grid, std::span<const Vec<D, R>> positions, R radius, NeighborLists& out);

  /// Rebuilds only the lists of the particles with `rebuild[i] != 0` and keeps the others as
  /// they are in `lists`. `lists` may cover fewer particles than `positions` (particles were
  /// appended): every particle beyond it must be marked. The grid must be built on
  /// `positions`. Deterministic for any thread count; allocates nothing in steady state.
  void rebuild_some(const UniformGrid<D, R>& grid, std::span<const Vec<D, R>> positions, R radius,
                    std::span<const std::uint8_t> rebuild, NeighborLists& lists);

 private:
  /// Gathers the list of particle i into buf and returns its length.
  /// Sets out.offsets from counts_ (prefix sum) and sizes out.indices to match.
  void set_offsets(std::size_t n, NeighborLists& out) const;
  static std::uint32_t gather(const UniformGrid<D, R>& grid, std::span<const Vec<D, R>> positions, R r2, std::size_t i,
                              std::vector<std::uint32_t>& buf);

  std::vector<std::vector<std::uint32_t>> chunk_indices_;
  std::vector<std::uint32_t> counts_;
  NeighborLists scratch_;
};

extern template class ListBuilder<2, float>;
extern template class ListBuilder<2, double>;
extern template class ListBuilder<3, float>;
extern template class ListBuilder<3, double>;

}  // namespace sph
