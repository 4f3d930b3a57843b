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

 private:
  std::vector<std::vector<std::uint32_t>> chunk_indices_;
  std::vector<std::uint32_t> counts_;
};

extern template class ListBuilder<2, float>;
extern template class ListBuilder<2, double>;
extern template class ListBuilder<3, float>;
extern template class ListBuilder<3, double>;

}  // namespace sph
